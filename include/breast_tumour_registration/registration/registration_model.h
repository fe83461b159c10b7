// The prepared prone model that every registration step works on: the prone tetrahedral
// mesh, its rest shape (the prone shape itself, as in thesis Sec. 5.2.3, or the estimated
// unloaded shape when the prone gravity is known), the fixed chest
// wall, the skin, per-element materials (a stiffer tumour when asked) and the tumours
// embedded barycentrically. Built once; the ROS node caches it.
#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "breast_tumour_registration/fem/elastic_energy.h"
#include "breast_tumour_registration/fem/material_parameters.h"
#include "breast_tumour_registration/fem/newton_solver.h"
#include "breast_tumour_registration/fem/stable_neo_hookean.h"
#include "breast_tumour_registration/geometry/embedding.h"

namespace btr {


struct StepReport {
  std::string name;
  bool converged = false;
  std::string stop_reason;
  std::string note;          ///< something the step limited or changed, for the warnings (empty: none)
  int iterations = 0;        ///< Newton iterations (all outer loops)
  int outer_iterations = 0;  ///< surface projections
  double seconds = 0;
  double energy = 0;
  double gradient_norm = 0;
  double projection_max_change = 0;  ///< surface step: the largest motion of a held skin vertex between the last two projections [m]
  /// surface step: the contraction of the alternation measured over the last iterates, the
  /// skin's estimated RMS distance from its fixed point at the end [m] (infinite: not
  /// contracting), and the projections that took an Anderson-accelerated iterate
  double contraction = 0, fixed_point_distance = 0;
  int accelerated_projections = 0;
  /// surface step: the projection from which the skin's sliding along the scan was held where
  /// it settled (SkinSliding::HeldWhereSettled; 0: free throughout)
  int sliding_held_from = 0;
  /// surface step: where the steps read a freely sliding skin as settled, the RMS distance [m] to
  /// the free limit that one Newton step without the point springs gives (SurfaceStepOptions::
  /// verify_free_limit), the projection it was checked at, and whether it lay beyond the
  /// tolerance (the steps had missed a slow slide; then that check's figures are kept). 0 / 0 /
  /// false: not checked.
  double free_limit_distance = 0;
  int free_limit_checked_at = 0;
  bool free_limit_missed = false;
  /// surface step: the held skin's RMS motion [m] at each projection, in order (how the
  /// alternation converged, stalled or jittered)
  std::vector<double> projection_residuals;
  /// surface step: RMS motion of the held skin between the last two projections [m] (0: none yet)
  double projection_rms_change() const { return projection_residuals.empty() ? 0.0 : projection_residuals.back(); }
  /// surface step: skin vertices constrained by the last projection (the others were too
  /// far from the supine surface or projected onto its border) and all skin vertices
  int constrained_skin = 0, skin_vertices = 0;
  /// Where the time went [s]: setup (energies, subspace, symbolic analysis), Hessian
  /// assembly, numeric factorizations, linear solves (PCG included), line search and the
  /// surface projections; with the number of factorizations and PCG iterations.
  double t_setup = 0, t_assembly = 0, t_factorization = 0, t_solve = 0, t_line_search = 0, t_projection = 0;
  int factorizations = 0, pcg_iterations = 0;
  /// unload step: max |phi(rest) - prone| [m], its cost in forward-solve equivalents, how far
  /// the rest shape moved from the prone one [m] and the load-continuation fractions it needed
  struct UnloadFigures {
    double mismatch = 0, forward_solve_equivalents = 0, rest_change = 0;
    int load_steps = 0;
    ElementOrder elements = ElementOrder::Linear;  ///< whose forward model the rest shape inverts
  } unload;
  /// stiffness step: the estimated Young's modulus [Pa] and the landmark misfit of its gravity-only prediction [m]
  double stiffness_youngs_modulus = 0, stiffness_misfit = 0;
  long inverted = 0;                ///< inverted tetrahedra at the end of the step
  bool inversions_allowed = false;  ///< a stall made the line search accept new inversions
  /// Adds a Newton solve's time split and counts (and its inversion state: the latest).
  void add_newton_profile(const NewtonResult& r) {
    inverted = r.inverted;
    inversions_allowed = inversions_allowed || r.inversions_allowed;
    add_newton_times(r);
  }
  /// A solve's times and counts only (a side solve whose inversions are not the step's).
  void add_newton_times(const NewtonResult& r) {
    t_assembly += r.t_assembly;
    t_factorization += r.t_factorization;
    t_solve += r.t_solve;
    t_line_search += r.t_line_search;
    factorizations += r.factorizations;
    pcg_iterations += r.pcg_iterations;
  }
};

struct EmbeddedTumour {
  std::string name;
  SurfaceMesh prone;      ///< in the model frame
  Embedding embedding;    ///< of prone.V in the rest mesh
};

struct RegistrationModel {
  /// The rest (stress-free) shape, model frame [m]: the prone mesh itself (thesis Sec. 5.2.3),
  /// or the unloaded shape estimated from it when the prone gravity is known (unload_step.h).
  TetMesh rest;
  /// The imaged prone positions [m] (rest.T's vertices): what the landmarks, tumours and rigid
  /// regions were given on. Equal to rest.V unless unloaded. (Registrations start from rest.V.)
  Points prone;
  std::optional<StepReport> unload;  ///< the unload step's report, when the rest shape was estimated
  /// The gravity the rest shape was unloaded under, model frame [m/s^2]; zero when the rest
  /// shape is the prone shape. An unloaded rest shape moves with the material (the linear
  /// region follows it: tumour_uncertainty.h).
  Vec3 unloaded_under = Vec3::Zero();
  /// Where the rest shape inverts the quadratic model (unload->unload.elements quadratic): that
  /// model's equilibrium from it, every node (UnloadResult::resimulated_nodes), where the linear
  /// region linearises the unload's equation. Empty otherwise, or when not kept (then solved
  /// again there).
  Points unloaded_nodes;
  std::vector<int> chest_wall;     ///< fixed vertices
  std::vector<bool> fixed;         ///< #V flags
  std::vector<int> skin;           ///< boundary vertices that are not fixed
  std::vector<StableNeoHookean> materials;  ///< [0] the body's; then regions' and the tumours' (material_regions.h)
  std::vector<int> material_of;    ///< per tetrahedron, into materials
  std::vector<std::string> material_names;  ///< per material: "body", a region's name, "tumour"
  std::vector<long> material_tetrahedra;    ///< per material: how many tetrahedra have it
  MaterialParameters material;
  VolumeForm volume_form = VolumeForm::Element;  ///< resolved from material (never Auto)
  double volume = 0;               ///< [m^3]
  Vec3 gravity = Vec3(0, 0, -9.81);///< supine gravity in the model frame [m/s^2]
  std::vector<EmbeddedTumour> tumours;
  long stiff_tetrahedra = 0;       ///< tetrahedra given the tumour material
};

/// Validates the mesh and indices and builds the model. Throws InputError on bad input.
RegistrationModel make_registration_model(const TetMesh& prone, const std::vector<int>& chest_wall,
                                          const MaterialParameters& material, const Vec3& gravity);

/// Embeds a tumour (closed surface in the model frame). Outside vertices are attached to
/// the nearest tetrahedron; the returned count says how many (the caller warns).
int add_tumour(RegistrationModel& model, const std::string& name, const SurfaceMesh& tumour);

/// Gives the tetrahedra whose centroid lies inside any tumour the material with Young's
/// modulus `youngs_modulus` (same nu), over any region's; addresses the thesis's flattened
/// tumours (Ch. 6). Appends the material "tumour".
void stiffen_tumours(RegistrationModel& model, double youngs_modulus);

/// Recounts model.material_tetrahedra from model.material_of.
void count_material_tetrahedra(RegistrationModel& model);

/// The model's elastic energy (material, volume form) added to `energy`: what every step simulates.
void add_model_elastic_energy(TotalEnergy& energy, const RegistrationModel& model);

/// Progress of a running step: step name and iteration; return false to abort.
using StepCallback = std::function<bool(const std::string& step, const IterationInfo& it)>;


}  // namespace btr
