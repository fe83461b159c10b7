// Gravitational potential with lumped masses: E = -sum_i m_i g . x_i (thesis Sec. 3.2),
// m_i = density * (quarter of the incident rest volumes).
#pragma once

#include "breast_tumour_registration/fem/energy_term.h"

namespace btr {

class GravityEnergy : public EnergyTerm {
 public:
  /// rest      rest mesh (masses); density [kg/m^3]; gravity acceleration vector [m/s^2]
  GravityEnergy(const TetMesh& rest, double density, const Vec3& gravity);
  /// Given nodal masses [kg] (e.g. a quadratic mesh's consistent ones, some negative).
  GravityEnergy(Eigen::VectorXd masses, const Vec3& gravity);
  std::string name() const override { return "gravity"; }
  double value(const Points& x) const override;
  void add_gradient(const Points& x, Eigen::VectorXd& g) const override;
  void add_hessian(const Points&, bool, HessianAssembler&) const override {}  // linear: zero Hessian

  const Eigen::VectorXd& masses() const { return masses_; }
  const Vec3& gravity() const { return gravity_; }
  /// |total gravitational force| [N], a natural force scale for convergence tests.
  double total_weight() const { return masses_.sum() * gravity_.norm(); }

 private:
  Eigen::VectorXd masses_;
  Vec3 gravity_;
};

}  // namespace btr
