// Soft point-to-plane constraints c(x) = w/2 ((p(x) - q) . n)^2 (thesis eq. 4.3): the
// anchored point may slide in the tangent plane through q with unit normal n.
#pragma once

#include <vector>

#include "breast_tumour_registration/fem/energy_term.h"
#include "breast_tumour_registration/geometry/anchor.h"

namespace btr {

class PlaneConstraintEnergy : public EnergyTerm {
 public:
  /// weight [N/m], applied to every constraint; must be finite and >= 0.
  explicit PlaneConstraintEnergy(double weight);
  /// normal is normalized here; throws InputError for a zero or non-finite normal.
  void add(const Anchor& anchor, const Vec3& point, const Vec3& normal);
  void clear();
  std::size_t size() const { return anchors_.size(); }

  std::string name() const override { return "plane"; }
  double value(const Points& x) const override;
  void add_gradient(const Points& x, Eigen::VectorXd& g) const override;
  void add_hessian(const Points& x, bool project_psd, HessianAssembler& H) const override;

 private:
  double weight_;
  std::vector<Anchor> anchors_;
  std::vector<Vec3> points_;
  std::vector<Vec3> normals_;
};

}  // namespace btr
