#include "breast_tumour_registration/fem/rigid_free_landmark_energy.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/fem/small_matrices.h"

namespace btr {
RigidFreeLandmarkEnergy::RigidFreeLandmarkEnergy(double weight, std::vector<Anchor> anchors, Points data)
    : weight_(weight), anchors_(std::move(anchors)), data_(std::move(data)) {
  if (!std::isfinite(weight) || weight < 0)
    throw InputError("landmark weight must be finite and >= 0, got " + std::to_string(weight));
  if (static_cast<Eigen::Index>(anchors_.size()) != data_.rows())
    throw InputError("pose-free landmarks: " + std::to_string(anchors_.size()) + " anchors but " +
                     std::to_string(data_.rows()) + " data points");
  if (anchors_.size() < 3) throw InputError("solving the pose with the landmarks needs at least 3 of them");
  if (!data_.allFinite()) throw InputError("pose-free landmarks: NaN or infinite landmark coordinates");
}

Points RigidFreeLandmarkEnergy::anchor_positions(const Points& x) const {
  Points a(anchors_.size(), 3);
  for (size_t i = 0; i < anchors_.size(); ++i) a.row(i) = anchors_[i].position(x).transpose();
  return a;
}

Rigid RigidFreeLandmarkEnergy::pose(const Points& x) const { return kabsch(data_, anchor_positions(x)); }

double RigidFreeLandmarkEnergy::value(const Points& x) const {
  const Points a = anchor_positions(x);
  if (!a.allFinite()) return std::numeric_limits<double>::infinity();
  return 0.5 * weight_ * (a - transform_points(kabsch(data_, a), data_)).squaredNorm();
}

void RigidFreeLandmarkEnergy::add_gradient(const Points& x, Eigen::VectorXd& g) const {
  const Points a = anchor_positions(x);
  const Points q = transform_points(kabsch(data_, a), data_);
  for (size_t i = 0; i < anchors_.size(); ++i) {
    const Vec3 r = weight_ * (a.row(i) - q.row(i)).transpose();
    for (int k = 0; k < anchors_[i].count; ++k) g.segment<3>(3 * anchors_[i].v[k]) += anchors_[i].w[k] * r;
  }
}

void RigidFreeLandmarkEnergy::add_hessian(const Points& x, bool project_psd, HessianAssembler& H) const {
  const Eigen::Index n = static_cast<Eigen::Index>(anchors_.size());
  const Points a = anchor_positions(x);
  const Points q = transform_points(kabsch(data_, a), data_);
  const Vec3 c = q.colwise().mean().transpose();
  // J: derivative of the targets with respect to a twist (omega, v) about c.
  Eigen::MatrixXd J(3 * n, 6);
  Mat6 F = Mat6::Zero();  // f_TT / weight
  for (Eigen::Index i = 0; i < n; ++i) {
    const Vec3 s = q.row(i).transpose() - c;
    J.block<3, 3>(3 * i, 0) = -cross_matrix(s);
    J.block<3, 3>(3 * i, 3) = Mat3::Identity();
    if (!project_psd) {  // rotation curvature: r . d2(T p)/domega2
      const Vec3 r = (a.row(i) - q.row(i)).transpose();
      F.topLeftCorner<3, 3>() -= 0.5 * (r * s.transpose() + s * r.transpose()) - r.dot(s) * Mat3::Identity();
    }
  }
  F += J.transpose() * J;
  const Mat6 M = symmetric_pseudo_inverse(F);  // landmarks on a line leave the rotation about it free
  const Eigen::MatrixXd P = Eigen::MatrixXd::Identity(3 * n, 3 * n) - J * M * J.transpose();
  for (Eigen::Index i = 0; i < n; ++i)
    for (Eigen::Index j = 0; j < n; ++j) {
      const Mat3 B = weight_ * P.block<3, 3>(3 * i, 3 * j);
      const Anchor &ai = anchors_[i], &aj = anchors_[j];
      for (int k = 0; k < ai.count; ++k)
        for (int l = 0; l < aj.count; ++l) H.add_block(ai.v[k], aj.v[l], ai.w[k] * aj.w[l] * B);
    }
}

std::vector<int> RigidFreeLandmarkEnergy::clique() const {
  std::vector<int> v;
  for (const Anchor& a : anchors_) v.insert(v.end(), a.v, a.v + a.count);
  std::sort(v.begin(), v.end());
  v.erase(std::unique(v.begin(), v.end()), v.end());
  return v;
}

}  // namespace btr
