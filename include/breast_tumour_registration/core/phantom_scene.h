// Writes a complete phantom scene (thesis Sec. 5.2.1) to a folder: rest/prone/supine
// meshes, tumours in each configuration, chest wall, chest ring, landmarks and scene.yaml,
// ready for load_scene. Used by btr_phantom, the tests and the experiments.
#pragma once

#include <functional>
#include <string>

#include "breast_tumour_registration/core/newton_solver.h"
#include "breast_tumour_registration/core/phantom.h"
#include "breast_tumour_registration/core/units.h"

namespace btr {

struct PhantomSceneOptions {
  PhantomOptions phantom;
  double youngs_modulus = 3400;  ///< generating material [Pa]
  double poisson_ratio = 0.49;
  double density = 1000;
  LengthUnit units = LengthUnit::Millimetre;
  std::string landmark_set = "C+O";
  /// > 0: the tumours' elements get this Young's modulus when generating prone and supine
  /// (real tumours are stiffer than the breast, thesis Ch. 6); 0: homogeneous.
  double tumour_youngs_modulus = 0;
};

struct PhantomSceneSummary {
  long vertices = 0, tetrahedra = 0, chest_wall_vertices = 0;
  TetQuality quality;
  NewtonResult prone, supine;
  std::vector<std::pair<std::string, double>> tumour_displacement;  ///< prone -> supine centroid [m]
};

/// Generates and writes the scene into `dir` (created). `progress` (optional) sees every
/// Newton iteration of the "prone" and "supine" solves. Throws InputError / SolverError.
PhantomSceneSummary write_phantom_scene(const std::string& dir, const PhantomSceneOptions& opt,
                                        const std::function<bool(const std::string&, const IterationInfo&)>& progress = {});

}  // namespace btr
