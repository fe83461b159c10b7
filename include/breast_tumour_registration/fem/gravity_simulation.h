// Quasi-static equilibrium of an elastic body under gravity with fixed vertices: the
// building block of the phantom's prone and supine configurations and of the optional
// gravity pre-step of the registration.
#pragma once

#include <vector>

#include "breast_tumour_registration/fem/elastic_energy.h"
#include "breast_tumour_registration/fem/newton_solver.h"
#include "breast_tumour_registration/fem/stable_neo_hookean.h"

namespace btr {

struct GravityProblem {
  const TetMesh* rest = nullptr;      ///< rest configuration
  std::vector<int> fixed;             ///< fixed vertices (keep their rest positions)
  double youngs_modulus = 3400;       ///< [Pa]
  double poisson_ratio = 0.49;
  double density = 1000;              ///< [kg/m^3]
  Vec3 gravity = Vec3(0, 0, -9.81);   ///< [m/s^2]
  /// Heterogeneous tissue: per tetrahedron 0 (youngs_modulus) or k >= 1 (region_youngs_modulus[k - 1]),
  /// all with the same Poisson's ratio; empty: homogeneous.
  std::vector<int> material_of;
  std::vector<double> region_youngs_modulus;  ///< [Pa]
  VolumeForm volume_form = VolumeForm::Auto;  ///< see elastic_energy.h
  double nodal_element_share = 0;             ///< MaterialParameters::nodal_element_share
};

struct GravityResult {
  Points x;            ///< equilibrium positions
  NewtonResult newton;
};

/// Solves for the equilibrium starting from the rest shape. Throws InputError for bad
/// parameters (via the material and energies) and SolverError for numerical failure.
GravityResult solve_gravity(const GravityProblem& problem, const NewtonOptions& options);

}  // namespace btr
