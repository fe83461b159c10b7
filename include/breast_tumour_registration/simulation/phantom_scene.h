// Writes a complete phantom scene (thesis Sec. 5.2.1) to a folder: rest/prone/supine
// meshes, tumours in each configuration, chest wall, chest ring, landmarks and scene.yaml,
// ready for load_scene. Used by btr_phantom, the tests and the experiments.
#pragma once

#include "breast_tumour_registration/fem/elastic_energy.h"

#include <functional>
#include <map>
#include <string>
#include <vector>

#include "breast_tumour_registration/base/units.h"
#include "breast_tumour_registration/fem/element_order.h"
#include "breast_tumour_registration/fem/newton_solver.h"
#include "breast_tumour_registration/simulation/phantom.h"

namespace btr {

struct PhantomSceneOptions {
  PhantomOptions phantom;
  double youngs_modulus = 3400;  ///< generating material [Pa]
  double poisson_ratio = 0.49;
  double density = 1000;
  VolumeForm volume_form = VolumeForm::Auto;  ///< of the generating material (elastic_energy.h)
  double nodal_element_share = 0;  ///< with the nodal form (MaterialParameters::nodal_element_share)
  LengthUnit units = LengthUnit::Millimetre;
  std::string landmark_set = "C+O";
  /// > 0: the tumours' elements get this Young's modulus when generating prone and supine
  /// (real tumours are stiffer than the breast, thesis Ch. 6); 0: homogeneous.
  double tumour_youngs_modulus = 0;
  /// > 0: the fibroglandular region (PhantomModel::gland) gets this Young's modulus (real
  /// glandular tissue is about 2x stiffer than fat); 0: the body's material.
  double gland_youngs_modulus = 0;
  /// The generating elements. Linear: the method's own kind, so a truth that flatters it (its
  /// linear tetrahedra sag too little on a coarse mesh, and so does the truth). Quadratic: the
  /// prone and supine equilibria with 10-node tetrahedra on the same mesh (ForwardGravity; the
  /// volume form does not apply), the tumours and gland carried by the quadratic field, the
  /// written meshes the corner vertices; a truth nearer the converged answer.
  ElementOrder element_order = ElementOrder::Linear;
};

/// Cell labels of a heterogeneous phantom's tetrahedra (fat everywhere, then gland, then
/// tumour, by centroid): what prone.vtk carries and the scene's regions refer to.
constexpr int kPhantomFatLabel = 1, kPhantomGlandLabel = 2, kPhantomTumourLabel = 3;
/// The labels the generating materials of `opt` call for; empty when homogeneous.
std::vector<int> phantom_tissue_labels(const PhantomModel& model, const PhantomSceneOptions& opt);

struct PhantomSceneSummary {
  long vertices = 0, tetrahedra = 0, chest_wall_vertices = 0;
  TetQuality quality;
  NewtonResult prone, supine;
  /// Quadratic truth whose straight corner tetrahedra invert prone: the scene's prone model is
  /// prone_surface.obj with prone.cell_size_mm (the method tetrahedralizes it), its chest wall
  /// and landmarks numbered on that surface and its regions closed surfaces; no prone.vtk.
  bool prone_written_as_surface = false;
  std::vector<std::pair<std::string, double>> tumour_displacement;  ///< prone -> supine centroid [m]
};

/// The prone and supine configurations a generating material gives a rest model: gravity
/// along +z (prone) and -z (supine) with the chest wall fixed, tumours carried along by
/// their rest embedding.
struct PhantomConfigurations {
  Points prone, supine;
  NewtonResult prone_newton, supine_newton;
  std::map<std::string, SurfaceMesh> tumour_prone, tumour_supine;
  SurfaceMesh gland_prone;  ///< the gland region's surface prone, when the model has one
  /// Quadratic truth: the straight tetrahedra between the elements' corners that are inverted,
  /// prone and supine (the mesh prone.vtk and supine.vtk would hold, and the method's unless it
  /// is re-meshed); the curved elements may hold where these do not. 0 for a linear truth (one
  /// with an inverted tetrahedron is refused).
  long prone_corner_inversions = 0, supine_corner_inversions = 0;
  std::vector<int> labels;  ///< phantom_tissue_labels (empty: homogeneous)
};

/// Simulates the configurations of `model` with the generating material and elements of `opt`
/// (the phantom geometry options are not used). Throws InputError for bad parameters or a
/// tumour outside the mesh, SolverError when a solve does not converge.
PhantomConfigurations simulate_phantom(const PhantomModel& model, const PhantomSceneOptions& opt,
                                       const std::function<bool(const std::string&, const IterationInfo&)>& progress = {});

/// Generates and writes the scene into `dir` (created). `progress` (optional) sees every
/// Newton iteration of the "prone" and "supine" solves. Throws InputError / SolverError (also
/// for a quadratic truth whose prone skin, the corners' boundary, intersects itself).
PhantomSceneSummary write_phantom_scene(const std::string& dir, const PhantomSceneOptions& opt,
                                        const std::function<bool(const std::string&, const IterationInfo&)>& progress = {});

}  // namespace btr
