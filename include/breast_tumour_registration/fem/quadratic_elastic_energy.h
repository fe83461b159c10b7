// The stable Neo-Hookean energy of quadratic (10-node) tetrahedra, integrated by a symmetric
// quadrature rule: E = sum_t vol_t sum_q w_q psi(F_q), F_q = sum_a x_a (grad N_a(b_q))^T.
// The positions are the quadratic mesh's nodes (corners first, then edge nodes,
// quadratic_tetrahedra.h); the rest shape is straight-sided. The projected Hessian clamps each
// quadrature point's d2psi/dF2 (positive weights keep the sum PSD).
//
// Near incompressibility a quadratic element still locks a little (SfePy's P2 truth sags 1.6 mm
// less than its P3 one at fat 500 Pa). QuadraticVolume::ElementMean moves the volume term onto
// the element's mean volume change Jbar = sum_q w_q J_q (mean dilatation, a P2/P0 element):
//   psi_q = mu/2 (I_C - 3) - mu (J_q - 1) + mu/2 (J_q - 1)^2  at each point (the stable
//           Neo-Hookean with lambda_L = 0: a positive bulk modulus 2 mu / 3, so a volume change
//           that varies inside the element with zero mean is no free mode),
//   plus lambda_L / 2 (Jbar - 1)^2 per element, lambda_L the classical Lame parameter.
// The same energy under a uniform deformation.
#pragma once
#pragma once

#include <string>
#include <vector>

#include "breast_tumour_registration/fem/energy_term.h"
#include "breast_tumour_registration/fem/quadratic_tetrahedra.h"
#include "breast_tumour_registration/fem/stable_neo_hookean.h"

namespace btr {

/// Where the volume term of a quadratic element acts: at every quadrature point, or on the
/// element's mean volume change (see above).
enum class QuadraticVolume { Quadrature, ElementMean };

using Vec30 = Eigen::Matrix<double, 30, 1>;
using Mat30 = Eigen::Matrix<double, 30, 30>;

class QuadraticElasticEnergy : public EnergyTerm {
 public:
  /// rest_corners  the linear mesh's rest vertex positions (the edge nodes at midpoints)
  /// materials, material_of  as ElasticEnergy's (per element)
  /// quadrature_degree  2 (4 points) or 5 (14 points), tet_quadrature
  /// Throws InputError on a degenerate or inverted rest element.
  QuadraticElasticEnergy(const QuadraticTetMesh& mesh, const Points& rest_corners,
                         std::vector<StableNeoHookean> materials, std::vector<int> material_of = {},
                         int quadrature_degree = 5, QuadraticVolume volume = QuadraticVolume::Quadrature);

  std::string name() const override { return "elastic_p2"; }
  double value(const Points& x) const override;
  void add_gradient(const Points& x, Eigen::VectorXd& g) const override;
  void add_hessian(const Points& x, bool project_psd, HessianAssembler& H) const override;
  /// The 10 nodes of every element.
  std::vector<std::vector<int>> hessian_cliques() const override;

  double element_value(const Points& x, Eigen::Index t) const;
  Vec30 element_gradient(const Points& x, Eigen::Index t) const;
  Mat30 element_hessian(const Points& x, Eigen::Index t, bool project_psd) const;

  /// Consistent nodal masses [kg] of a uniform density: the integral of density times each shape
  /// function (a corner's is negative, -1/20 of its element's mass; an edge node's 1/5).
  Eigen::VectorXd consistent_masses(double density) const;

 private:
  Eigen::Matrix<double, 10, 3> shape_gradients(Eigen::Index t, size_t q) const;
  /// ElementMean: the element's mean volume change at node positions X (3 x 10).
  double mean_volume_change(const Eigen::Matrix<double, 3, 10>& X, Eigen::Index t) const;

  QuadraticTets T_;
  Eigen::Index nodes_;
  std::vector<Eigen::Matrix<double, 4, 3>> barycentric_gradients_;  ///< per element
  std::vector<double> volume_;
  std::vector<StableNeoHookean> materials_;
  std::vector<int> material_of_;
  std::vector<TetQuadraturePoint> rule_;
  QuadraticVolume volume_form_;
  std::vector<StableNeoHookean> local_;  ///< ElementMean: per material, its shear part with lambda_L = 0
  std::vector<double> lambda_lame_;      ///< ElementMean: per material, lambda_L on the mean
  std::vector<Eigen::Matrix<double, 10, 4>> shape_derivatives_;  ///< per quadrature point
  mutable ElementScatter<10> scatter_;  ///< built on first use per assembler
};

}  // namespace btr
