// Soft point constraints c(x) = w/2 |p(x) - target|^2 (thesis eq. 4.2), where p(x) is
// an Anchor (vertex or barycentric point). Used for landmarks and surface projection.
#pragma once

#include <vector>

#include "breast_tumour_registration/fem/energy_term.h"
#include "breast_tumour_registration/geometry/anchor.h"

namespace btr {

class PointConstraintEnergy : public EnergyTerm {
 public:
  /// weight [N/m], applied to every constraint; must be finite and >= 0.
  explicit PointConstraintEnergy(double weight);
  void add(const Anchor& anchor, const Vec3& target);
  void clear();
  std::size_t size() const { return anchors_.size(); }
  double weight() const { return weight_; }

  std::string name() const override { return "point"; }
  double value(const Points& x) const override;
  void add_gradient(const Points& x, Eigen::VectorXd& g) const override;
  void add_hessian(const Points& x, bool project_psd, HessianAssembler& H) const override;

  const std::vector<Anchor>& anchors() const { return anchors_; }
  const std::vector<Vec3>& targets() const { return targets_; }

 private:
  double weight_;
  std::vector<Anchor> anchors_;
  std::vector<Vec3> targets_;
};

}  // namespace btr
