#include "breast_tumour_registration/fem/point_constraint_energy.h"

#include <cmath>
#include <string>

#include "breast_tumour_registration/base/errors.h"

namespace btr {

PointConstraintEnergy::PointConstraintEnergy(double weight) : weight_(weight) {
  if (!std::isfinite(weight) || weight < 0)
    throw InputError("point constraint weight must be finite and >= 0, got " + std::to_string(weight));
}

void PointConstraintEnergy::add(const Anchor& anchor, const Vec3& target) {
  if (!target.allFinite()) throw InputError("point constraint target is not finite");
  anchors_.push_back(anchor);
  targets_.push_back(target);
}

void PointConstraintEnergy::clear() {
  anchors_.clear();
  targets_.clear();
}

double PointConstraintEnergy::value(const Points& x) const {
  double e = 0;
  for (size_t i = 0; i < anchors_.size(); ++i) e += 0.5 * weight_ * (anchors_[i].position(x) - targets_[i]).squaredNorm();
  return e;
}

void PointConstraintEnergy::add_gradient(const Points& x, Eigen::VectorXd& g) const {
  for (size_t i = 0; i < anchors_.size(); ++i) {
    const Anchor& a = anchors_[i];
    const Vec3 r = weight_ * (a.position(x) - targets_[i]);
    for (int k = 0; k < a.count; ++k) g.segment<3>(3 * a.v[k]) += a.w[k] * r;
  }
}

void PointConstraintEnergy::add_hessian(const Points&, bool, HessianAssembler& H) const {
  // w (sum_k w_k e_k)(sum_l w_l e_l)^T (x) I3: PSD already, nothing to project.
  for (const Anchor& a : anchors_)
    for (int k = 0; k < a.count; ++k)
      for (int l = 0; l < a.count; ++l) H.add_block(a.v[k], a.v[l], weight_ * a.w[k] * a.w[l] * Mat3::Identity());
}

}  // namespace btr
