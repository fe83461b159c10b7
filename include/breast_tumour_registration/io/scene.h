// A registration scene (YAML): what is known about one patient (or phantom). Paths are
// relative to the scene file; lengths in files use `units` and are converted once here.
//
//   units: mm                      # m or mm (required)
//   prone:
//     tet_mesh: prone.vtk          # or `surface: prone.obj` to tetrahedralize (cell_size_mm)
//     cell_size_mm: 6              # with surface: the size it is meshed at; with tet_mesh: the size
//                                  # it was made at (a call re-meshes it only for clearly coarser cells)
//     tumour_cell_size_mm: 4       # optional: where a call meshes the prone model, finer cells
//                                  # around each tumour (0: none; default: the preset's)
//   chest_wall: chest_wall.txt     # vertex indices of prone.tet_mesh (or of prone.surface)
//   chest_ring: chest_ring.obj     # optional: prone rigid skin around the breast (for ICP)
//   landmarks: landmarks.csv       # optional: prone index with supine index or supine x,y,z
//   # landmarks: {prone: prone.mrk.json, supine: supine.mrk.json}   # or Slicer point lists,
//   patient_frame: RAS             # matched by label; then the scene says its frame (RAS or LPS)
//   supine:
//     surface: supine.obj          # optional: supine surface (closed mesh or open scan)
//     denoise: auto                # optional: auto (a noisy surface is denoised) or off
//     cloud: scan.xyz              # optional instead of surface: unorganized points (.xyz, .ply, .obj)
//     chest_ring: ring.obj         # optional: supine rigid region (for ICP)
//   tumours: [{name: t1, prone: t1.obj, supine_ground_truth: t1_supine.obj}]
//   material: {youngs_modulus: 3400, poisson_ratio: 0.49, density: 1000}
//                                  # youngs_modulus: estimate (with prone_gravity and >= 3 landmarks):
//                                  # the step `stiffness` finds it, in youngs_modulus_range: [150, 24000]
//   regions:                       # optional: per-element materials (material_regions.h), later wins
//     - {name: gland, label: 2, youngs_modulus: 6800}          # cell label of prone.tet_mesh
//     - {name: gland, surface: gland.obj, relative_stiffness: 2} # or a closed surface (model frame);
//                                  # relative_stiffness: times material.youngs_modulus (scaled with an estimate)
//                                  # prone.cell_labels: names the cell array when the file has several
//   tumour_material: {youngs_modulus: 17000}   # optional: stiffer tumour (over any region)
//   gravity: [0, 0, -9.81]         # supine gravity in the prone model frame [m/s^2] (required)
//   prone_gravity: [0, 0, 9.81]    # optional: the gravity the prone image was taken under, same
//                                  # frame; given, the step `unload` estimates the stress-free shape
//   steps: auto                    # or a list of: rigid, unload, gravity, landmarks, surface
//   preset: balanced               # fast, balanced, accurate
//   misalignment: {rotation_deg: [0, 0, 15], translation_mm: [0, 0, 0]}  # optional, experiments
//   uncertainty: {youngs_modulus_range: [200, 3000], landmark_sd_mm: 1.5}  # optional: the uncertain
//                                  # inputs' distributions (uncertainty_sources.h has every field)
#pragma once

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "breast_tumour_registration/base/units.h"
#include "breast_tumour_registration/fem/material_parameters.h"
#include "breast_tumour_registration/fem/material_region.h"
#include "breast_tumour_registration/geometry/anchor.h"
#include "breast_tumour_registration/geometry/label_volume.h"
#include "breast_tumour_registration/geometry/surface_attachment.h"
#include "breast_tumour_registration/geometry/rigid_transform.h"
#include "breast_tumour_registration/io/uncertainty_sources.h"

namespace btr {

struct SceneTumour {
  std::string name;
  SurfaceMesh prone;                               ///< model frame
  std::optional<SurfaceMesh> supine_ground_truth;  ///< supine frame
};

/// A prone model given as a closed surface: what meshing needs (the chest wall and the
/// landmarks refer to the surface's vertices and are re-attached to the tetrahedra).
struct ProneSurfaceSource {
  SurfaceMesh surface;
  std::vector<int> chest_wall;  ///< surface vertex indices
  Points landmarks;             ///< prone landmark points on the surface, one row per pair
  std::optional<double> cell_size;  ///< prone.cell_size_mm when the scene gives it [m]
};

/// Cell size a prone surface is tetrahedralized at when nothing else says [m].
constexpr double kDefaultCellSize = 0.006;

struct Scene {
  std::string path;
  LengthUnit units = LengthUnit::Millimetre;
  TetMesh prone;                         ///< model frame (empty for a prone surface until mesh_prone)
  /// `prone.cell_size_mm` with `prone.tet_mesh` [m]: the cell size the tetrahedral mesh was made
  /// at (btr_scene_from_labels states it). Where given, needs_simulation_mesh compares it with a
  /// call's size instead of reading the mesh's edges, which a label mesh's interfaces shorten.
  std::optional<double> prone_mesh_cell_size;
  std::optional<ProneSurfaceSource> prone_source;  ///< the prone model was given as a surface
  bool tetrahedralized = false;          ///< prone was meshed from prone_source
  double tetrahedralize_seconds = 0;
  std::vector<int> chest_wall;           ///< prone tet vertex indices
  std::vector<Anchor> landmark_anchors;  ///< prone landmark points
  std::vector<std::string> landmark_labels;  ///< one per anchor when the landmarks came from point lists
  std::optional<PatientFrame> patient_frame;  ///< `patient_frame`: the scene's coordinates in RAS or LPS
  Points landmark_supine;                ///< supine landmark positions (supine frame), one row per anchor
  std::optional<SurfaceMesh> supine_surface;  ///< supine frame
  std::optional<Points> supine_cloud;         ///< supine frame; used when there is no supine_surface
  /// `supine.denoise: auto | off`: whether a noisy supine surface may be denoised before the
  /// surface step (SurfaceStepOptions::scan_denoising_min_noise decides when)
  bool supine_denoise = true;
  std::optional<SurfaceMesh> prone_rigid;     ///< model frame
  std::optional<SurfaceMesh> supine_rigid;    ///< supine frame
  std::vector<SceneTumour> tumours;
  /// `prone.tumour_cell_size_mm` [m]: where the prone model is (re-)tetrahedralized for a call,
  /// cells of at most this size in each tumour's bounding ball, graded to the call's size around
  /// it (tumour_refinements in simulation_mesh.h); 0: none. Not stated: the preset's
  /// (RegistrationOptions::tumour_cell_size; the accurate preset 4 mm, the others none).
  /// BENCHMARKS.md, "Tumours the truth resolves" and "Finer cells around the tumours in the
  /// accurate preset".
  std::optional<double> tumour_cell_size;
  MaterialParameters material;
  /// Whether the scene states `material.unload_element_order`; where it does not, a preset may
  /// choose the unload's elements (RegistrationOptions::unload_element_order)
  bool unload_element_order_stated = false;
  /// `material.nodal_fallback` (default true): a registration with the nodal volume form that
  /// ends not converged is run again with the element form, and that result is returned
  /// (RegistrationEngine; RegistrationResult::volume_form_fallback says why)
  bool nodal_fallback = true;
  std::vector<MaterialRegion> regions;   ///< per-element materials, in order (later wins)
  std::vector<int> prone_labels;         ///< cell label per prone tetrahedron, when a region selects by label
  /// Labels a re-mesh (with_simulation_mesh) left on no tetrahedron of `prone`: their share goes
  /// to the tetrahedron holding them (assign_material_regions)
  std::vector<LabelRemnant> prone_label_remnants;
  std::optional<double> tumour_youngs_modulus;
  /// `youngs_modulus: estimate`: the range [Pa] the stiffness step searches (material.youngs_modulus
  /// is then only the reference the other materials are given relative to).
  std::optional<std::array<double, 2>> youngs_modulus_range;
  Vec3 gravity = Vec3(0, 0, -9.81);
  /// The gravity of the prone image, model frame [m/s^2]: given, the unload step runs (the
  /// model's rest shape becomes the estimated unloaded shape); absent, the prone shape is the rest shape.
  std::optional<Vec3> prone_gravity;
  std::vector<std::string> steps;        ///< empty: auto
  std::string preset = "balanced";
  Rigid misalignment = Rigid::Identity();  ///< already applied to all supine data
  UncertaintySources uncertainty;          ///< `uncertainty`: the defaults unless the scene overrides them
  std::vector<std::string> warnings;       ///< what loading repaired (e.g. flipped faces)
};

/// The misalignment of thesis Sec. 5.2.5: rotations about X, then Y, then Z (degrees,
/// about the model origin), then a translation (millimetres).
Rigid misalignment_from_degrees_mm(const Vec3& rotation_deg, const Vec3& translation_mm);

/// Moves all supine data of the scene (surface, cloud, rigid region, landmarks, ground
/// truth) by `m`, as if the supine scan had been taken misaligned; composes s.misalignment.
void apply_misalignment(Scene& s, const Rigid& m);

/// Loads and validates a scene: parses every field and reads the files it names, and meshes
/// nothing (a prone surface stays in prone_source, s.prone empty, for the registration layer's
/// mesh_prone at the size a call simulates). Throws InputError naming the file and field at
/// fault: a missing `units` or `gravity`, an unknown or misplaced key (with the nearest valid
/// one), a value of the wrong type, a mesh whose size says the units are wrong.
Scene load_scene(const std::string& path);

/// A prone landmark further than this from the prone skin is a frame or units mistake [m].
constexpr double kMaxLandmarkSkinDistance = 0.010;
/// InputError naming the landmark (by its label when given) that lies further than
/// kMaxLandmarkSkinDistance from the skin it was attached to.
void check_landmark_attachment(const BoundaryAttachment& a, const std::vector<std::string>& labels, const std::string& path);

/// Throws InputError (naming file and field) when a mesh's extent is not that of a breast
/// (1 cm to 3 m): most often a metre file read as millimetres, or the other way round.
void check_length_scale(const Points& V, LengthUnit units, const std::string& file, const std::string& field);

/// A closed surface with faces flipped against their neighbours or inwards is repaired
/// (orient_closed_surface); the count goes to `warnings`. Other defects throw InputError.
void repair_orientation(SurfaceMesh& m, const std::string& name, std::vector<std::string>& warnings);

}  // namespace btr
