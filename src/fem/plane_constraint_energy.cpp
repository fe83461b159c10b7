#include "breast_tumour_registration/fem/plane_constraint_energy.h"

#include <cmath>
#include <string>

#include "breast_tumour_registration/base/errors.h"

namespace btr {

PlaneConstraintEnergy::PlaneConstraintEnergy(double weight) : weight_(weight) {
  if (!std::isfinite(weight) || weight < 0)
    throw InputError("point-to-plane constraint weight must be finite and >= 0, got " + std::to_string(weight));
}

void PlaneConstraintEnergy::add(const Anchor& anchor, const Vec3& point, const Vec3& normal) {
  const double n = normal.norm();
  if (!point.allFinite() || !std::isfinite(n) || n == 0)
    throw InputError("point-to-plane constraint needs a finite point and a non-zero normal");
  anchors_.push_back(anchor);
  points_.push_back(point);
  normals_.push_back(normal / n);
}

void PlaneConstraintEnergy::clear() {
  anchors_.clear();
  points_.clear();
  normals_.clear();
}

double PlaneConstraintEnergy::value(const Points& x) const {
  double e = 0;
  for (size_t i = 0; i < anchors_.size(); ++i) {
    const double d = (anchors_[i].position(x) - points_[i]).dot(normals_[i]);
    e += 0.5 * weight_ * d * d;
  }
  return e;
}

void PlaneConstraintEnergy::add_gradient(const Points& x, Eigen::VectorXd& g) const {
  for (size_t i = 0; i < anchors_.size(); ++i) {
    const Anchor& a = anchors_[i];
    const double d = (a.position(x) - points_[i]).dot(normals_[i]);
    for (int k = 0; k < a.count; ++k) g.segment<3>(3 * a.v[k]) += weight_ * a.w[k] * d * normals_[i];
  }
}

void PlaneConstraintEnergy::add_hessian(const Points&, bool, HessianAssembler& H) const {
  // w (sum w_k e_k)(sum w_l e_l)^T (x) n n^T: PSD already.
  for (size_t i = 0; i < anchors_.size(); ++i) {
    const Anchor& a = anchors_[i];
    const Mat3 nn = normals_[i] * normals_[i].transpose();
    for (int k = 0; k < a.count; ++k)
      for (int l = 0; l < a.count; ++l) H.add_block(a.v[k], a.v[l], weight_ * a.w[k] * a.w[l] * nn);
  }
}

}  // namespace btr
