#include "breast_tumour_registration/fem/spring_energy.h"

#include <Eigen/Eigenvalues>

#include <cmath>
#include <string>

#include "breast_tumour_registration/base/errors.h"

namespace btr {
namespace {

void check_weight(double w, const char* what) {
  if (!std::isfinite(w) || w < 0)
    throw InputError(std::string(what) + " spring weight must be finite and >= 0, got " + std::to_string(w));
}

Vec3 unit_normal(const Vec3& normal) {
  const double n = normal.norm();
  if (!std::isfinite(n) || n == 0) throw InputError("point-to-plane spring needs a non-zero, finite normal");
  return normal / n;
}

}  // namespace

void SpringEnergy::add(const Anchor& anchor, const Vec3& target, const Mat3& K) {
  if (!K.allFinite() || (K - K.transpose()).cwiseAbs().maxCoeff() > 1e-12 * K.cwiseAbs().maxCoeff())
    throw InputError("spring stiffness must be a finite symmetric 3x3 matrix");
  const double lowest = Eigen::SelfAdjointEigenSolver<Mat3>(K, Eigen::EigenvaluesOnly).eigenvalues()[0];
  if (lowest < -1e-12 * K.cwiseAbs().maxCoeff()) throw InputError("spring stiffness must be positive semi-definite");
  push(anchor, target, K);
}

// The metrics below are symmetric PSD by construction (finite weights >= 0, a unit normal):
// the surface step adds one per held skin vertex and projection, without an eigensolve each.
void SpringEnergy::push(const Anchor& anchor, const Vec3& target, const Mat3& K) {
  if (!target.allFinite()) throw InputError("spring target is not finite");
  anchors_.push_back(anchor);
  targets_.push_back(target);
  stiffness_.push_back(K);
}

void SpringEnergy::add_point(const Anchor& anchor, const Vec3& target, double weight) {
  check_weight(weight, "point");
  push(anchor, target, weight * Mat3::Identity());
}

void SpringEnergy::add_plane(const Anchor& anchor, const Vec3& point, const Vec3& normal, double weight) {
  check_weight(weight, "point-to-plane");
  const Vec3 n = unit_normal(normal);
  push(anchor, point, weight * n * n.transpose());
}

void SpringEnergy::add_point_and_plane(const Anchor& anchor, const Vec3& point, const Vec3& normal, double point_weight,
                                       double plane_weight) {
  check_weight(point_weight, "point");
  check_weight(plane_weight, "point-to-plane");
  const Vec3 n = unit_normal(normal);
  push(anchor, point, point_weight * Mat3::Identity() + plane_weight * n * n.transpose());
}

void SpringEnergy::clear() {
  anchors_.clear();
  targets_.clear();
  stiffness_.clear();
}

double SpringEnergy::value(const Points& x) const {
  double e = 0;
  for (size_t i = 0; i < anchors_.size(); ++i) {
    const Vec3 d = anchors_[i].position(x) - targets_[i];
    e += 0.5 * d.dot(stiffness_[i] * d);
  }
  return e;
}

void SpringEnergy::add_gradient(const Points& x, Eigen::VectorXd& g) const {
  for (size_t i = 0; i < anchors_.size(); ++i) {
    const Anchor& a = anchors_[i];
    const Vec3 f = stiffness_[i] * (a.position(x) - targets_[i]);
    for (int k = 0; k < a.count; ++k) g.segment<3>(3 * a.v[k]) += a.w[k] * f;
  }
}

void SpringEnergy::add_hessian(const Points&, bool, HessianAssembler& H) const {
  // (sum_k w_k e_k)(sum_l w_l e_l)^T (x) K: PSD when K is, nothing to project.
  for (size_t i = 0; i < anchors_.size(); ++i) {
    const Anchor& a = anchors_[i];
    for (int k = 0; k < a.count; ++k)
      for (int l = 0; l < a.count; ++l) H.add_block(a.v[k], a.v[l], a.w[k] * a.w[l] * stiffness_[i]);
  }
}

}  // namespace btr
