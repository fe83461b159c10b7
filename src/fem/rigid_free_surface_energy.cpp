#include "breast_tumour_registration/fem/rigid_free_surface_energy.h"

#include <cmath>
#include <limits>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/fem/small_matrices.h"

namespace btr {

RigidFreeSurfaceEnergy::RigidFreeSurfaceEnergy(double point_weight, double plane_weight)
    : point_weight_(point_weight), plane_weight_(plane_weight) {
  if (!std::isfinite(point_weight) || !std::isfinite(plane_weight) || point_weight < 0 || plane_weight < 0 ||
      point_weight + plane_weight == 0)
    throw InputError("surface spring weights must be finite, >= 0 and not both 0");
}

void RigidFreeSurfaceEnergy::set(const std::vector<int>& vertices, const Points& y, const Points& n) {
  if (static_cast<Eigen::Index>(vertices.size()) != y.rows() || y.rows() != n.rows())
    throw InputError("pose-free surface springs: vertices, points and normals differ in number");
  if (!y.allFinite() || !n.allFinite()) throw InputError("pose-free surface springs: non-finite point or normal");
  surface_anchors_.clear();
  surface_y_.clear();
  surface_A_.clear();
  for (size_t j = 0; j < vertices.size(); ++j) {
    const Vec3 nj = n.row(static_cast<Eigen::Index>(j)).transpose();
    if (!(nj.norm() > 0)) throw InputError("pose-free surface springs: zero normal");
    const Vec3 u = nj.normalized();
    surface_anchors_.push_back(Anchor::vertex(vertices[j]));
    surface_y_.push_back(y.row(static_cast<Eigen::Index>(j)).transpose());
    surface_A_.push_back(point_weight_ * Mat3::Identity() + plane_weight_ * u * u.transpose());
  }
  rebuild();
}

void RigidFreeSurfaceEnergy::set_points(const std::vector<Anchor>& anchors, const Points& targets, double weight) {
  if (static_cast<Eigen::Index>(anchors.size()) != targets.rows())
    throw InputError("pose-free surface springs: anchors and targets differ in number");
  if (!targets.allFinite() || !std::isfinite(weight) || weight < 0)
    throw InputError("pose-free surface springs: non-finite point target or bad weight");
  point_anchors_ = anchors;
  point_y_.clear();
  point_A_.assign(anchors.size(), weight * Mat3::Identity());
  for (Eigen::Index j = 0; j < targets.rows(); ++j) point_y_.push_back(targets.row(j).transpose());
  rebuild();
}

void RigidFreeSurfaceEnergy::rebuild() {
  anchors_ = surface_anchors_;
  anchors_.insert(anchors_.end(), point_anchors_.begin(), point_anchors_.end());
  y_ = surface_y_;
  y_.insert(y_.end(), point_y_.begin(), point_y_.end());
  A_ = surface_A_;
  A_.insert(A_.end(), point_A_.begin(), point_A_.end());
}

Vec3 RigidFreeSurfaceEnergy::turning_centre(const Points& x, const Rigid& P) const {
  Vec3 c = Vec3::Zero();
  for (const Anchor& a : anchors_) c += P * a.position(x);
  return c / static_cast<double>(anchors_.size());
}

Eigen::Matrix<double, 3, 6> RigidFreeSurfaceEnergy::twist_jacobian(const Vec3& q, const Vec3& centre) {
  Eigen::Matrix<double, 3, 6> J;
  J << -cross_matrix(q - centre), Mat3::Identity();
  return J;
}

Rigid RigidFreeSurfaceEnergy::pose(const Points& x) const {
  if (anchors_.size() < 3) throw InputError("solving the pose on the surface needs at least 3 correspondences");
  Rigid P = warm_;
  for (int it = 0; it < 50; ++it) {
    const Vec3 c = turning_centre(x, P);
    Mat6 F = Mat6::Zero();
    Vec6 b = Vec6::Zero();
    for (size_t j = 0; j < anchors_.size(); ++j) {
      const Vec3 q = P * anchors_[j].position(x);
      const Eigen::Matrix<double, 3, 6> J = twist_jacobian(q, c);
      F += J.transpose() * A_[j] * J;
      b += J.transpose() * A_[j] * (q - y_[j]);
    }
    const Vec6 d = -symmetric_pseudo_inverse(F) * b;
    if (!d.allFinite()) throw SolverError("pose-free surface springs: pose update is not finite");
    const Vec3 w = d.head<3>();
    Rigid step = Rigid::Identity();
    if (w.norm() > 0) step.linear() = Eigen::AngleAxisd(w.norm(), w / w.norm()).toRotationMatrix();
    step.translation() = c - step.linear() * c + d.tail<3>();
    P = step * P;
    if (w.norm() < 1e-12 && d.tail<3>().norm() < 1e-12) break;  // radians, metres: at round-off
  }
  warm_ = P;
  return P;
}

double RigidFreeSurfaceEnergy::value(const Points& x) const {
  if (anchors_.empty()) return 0;
  for (const Anchor& a : anchors_)
    if (!a.position(x).allFinite()) return std::numeric_limits<double>::infinity();
  const Rigid P = pose(x);
  double e = 0;
  for (size_t j = 0; j < anchors_.size(); ++j) {
    const Vec3 r = P * anchors_[j].position(x) - y_[j];
    e += 0.5 * r.dot(A_[j] * r);
  }
  return e;
}

void RigidFreeSurfaceEnergy::add_gradient(const Points& x, Eigen::VectorXd& g) const {
  if (anchors_.empty()) return;
  const Rigid P = pose(x);
  const Mat3 Qt = P.linear().transpose();
  for (size_t j = 0; j < anchors_.size(); ++j) {
    const Anchor& a = anchors_[j];
    const Vec3 f = Qt * (A_[j] * (P * a.position(x) - y_[j]));
    for (int k = 0; k < a.count; ++k) g.segment<3>(3 * a.v[k]) += a.w[k] * f;
  }
}

void RigidFreeSurfaceEnergy::add_hessian(const Points& x, bool, HessianAssembler& H) const {
  if (anchors_.empty()) return;
  const Mat3 Q = pose(x).linear();
  for (size_t j = 0; j < anchors_.size(); ++j) {
    const Anchor& a = anchors_[j];
    const Mat3 B = Q.transpose() * A_[j] * Q;
    for (int k = 0; k < a.count; ++k)
      for (int l = 0; l < a.count; ++l) H.add_block(a.v[k], a.v[l], a.w[k] * a.w[l] * B);
  }
}

void RigidFreeSurfaceEnergy::add_low_rank_hessian(const Points& x, std::vector<LowRankHessian>& parts) const {
  if (anchors_.empty()) return;
  const Rigid P = pose(x);
  const Mat3 Qt = P.linear().transpose();
  const Vec3 c = turning_centre(x, P);
  LowRankHessian part;
  part.W.setZero(x.size(), 6);
  Mat6 F = Mat6::Zero();
  for (size_t j = 0; j < anchors_.size(); ++j) {
    const Anchor& a = anchors_[j];
    const Eigen::Matrix<double, 3, 6> J = twist_jacobian(P * a.position(x), c);
    F += J.transpose() * A_[j] * J;
    const Eigen::Matrix<double, 3, 6> QAJ = Qt * A_[j] * J;
    for (int k = 0; k < a.count; ++k) part.W.middleRows<3>(3 * a.v[k]) += a.w[k] * QAJ;
  }
  part.M = symmetric_pseudo_inverse(F);
  parts.push_back(std::move(part));
}

}  // namespace btr
