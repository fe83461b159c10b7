#include "breast_tumour_registration/geometry/rigid_transform.h"

#include <algorithm>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>
#include <cmath>

#include "breast_tumour_registration/base/errors.h"

namespace btr {

namespace {

// Second-largest over largest variance of the centred rows: 0 for collinear points.
double planarity(const Eigen::MatrixX3d& centred) {
  const Vec3 ev = Eigen::SelfAdjointEigenSolver<Mat3>(centred.transpose() * centred, Eigen::EigenvaluesOnly).eigenvalues();
  return ev[1] / std::max(ev[2], 1e-300);  // ascending order
}

}  // namespace

Rigid kabsch(const Points& source, const Points& target) {
  if (source.rows() != target.rows()) throw InputError("kabsch: point sets differ in size");
  if (source.rows() < 3) throw InputError("rigid alignment from landmarks needs at least 3 pairs, got " + std::to_string(source.rows()));
  if (!source.allFinite() || !target.allFinite()) throw InputError("kabsch: NaN or infinite landmark coordinates");
  const Eigen::MatrixX3d S = source.rowwise() - source.colwise().mean(), T = target.rowwise() - target.colwise().mean();
  if (planarity(S) <= 1e-12 || planarity(T) <= 1e-12)
    throw InputError("rigid alignment from landmarks: the landmarks are collinear (rotation undetermined)");
  // Umeyama (1991) without scaling, reflection excluded: Eigen's implementation.
  Rigid out = Rigid::Identity();
  out.matrix() = Eigen::umeyama(source.transpose(), target.transpose(), false);
  return out;
}

Points transform_points(const Rigid& T, const Points& P) {
  Points out(P.rows(), 3);
  for (Eigen::Index i = 0; i < P.rows(); ++i) out.row(i) = (T * Vec3(P.row(i).transpose())).transpose();
  return out;
}

SurfaceMesh transform_surface(const Rigid& T, const SurfaceMesh& s) { return {transform_points(T, s.V), s.F}; }

double rotation_angle(const Rigid& T) { return Eigen::AngleAxisd(T.rotation()).angle(); }

Rigid rigid_from_rpy(const Vec3& translation, const Vec3& roll_pitch_yaw) {
  Rigid T = Rigid::Identity();
  T.linear() = (Eigen::AngleAxisd(roll_pitch_yaw.z(), Vec3::UnitZ()) * Eigen::AngleAxisd(roll_pitch_yaw.y(), Vec3::UnitY()) *
                Eigen::AngleAxisd(roll_pitch_yaw.x(), Vec3::UnitX()))
                   .toRotationMatrix();
  T.translation() = translation;
  return T;
}

double max_displacement(const Rigid& A, const Rigid& B, const Points& P) {
  double worst = 0;
  for (Eigen::Index i = 0; i < P.rows(); ++i) {
    const Vec3 p = P.row(i).transpose();
    worst = std::max(worst, (A * p - B * p).norm());
  }
  return worst;
}

Rigid rigid_from_motion(const Vec6& xi) {
  Rigid T = Rigid::Identity();
  const double angle = xi.head<3>().norm();
  if (angle > 0) T.linear() = Eigen::AngleAxisd(angle, xi.head<3>() / angle).toRotationMatrix();
  T.translation() = xi.tail<3>();
  return T;
}

Vec6 motion_of(const Rigid& T) {
  const Eigen::AngleAxisd aa(T.linear());
  Vec6 xi;
  xi << aa.angle() * aa.axis(), T.translation();
  return xi;
}

}  // namespace btr
