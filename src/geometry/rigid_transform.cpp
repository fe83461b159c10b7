#include "breast_tumour_registration/geometry/rigid_transform.h"

#include <algorithm>

#include <Eigen/SVD>
#include <cmath>

#include "breast_tumour_registration/base/errors.h"

namespace btr {

Rigid kabsch(const Points& source, const Points& target) {
  if (source.rows() != target.rows()) throw InputError("kabsch: point sets differ in size");
  if (source.rows() < 3) throw InputError("rigid alignment from landmarks needs at least 3 pairs, got " + std::to_string(source.rows()));
  if (!source.allFinite() || !target.allFinite()) throw InputError("kabsch: NaN or infinite landmark coordinates");
  const Vec3 cs = source.colwise().mean().transpose(), ct = target.colwise().mean().transpose();
  const Eigen::MatrixX3d S = source.rowwise() - cs.transpose(), T = target.rowwise() - ct.transpose();
  const Mat3 C = S.transpose() * T;
  Eigen::JacobiSVD<Mat3> svd(C, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Vec3 sv = svd.singularValues();
  if (sv[1] <= 1e-12 * std::max(sv[0], 1e-300))
    throw InputError("rigid alignment from landmarks: the landmarks are collinear (rotation undetermined)");
  Mat3 D = Mat3::Identity();
  D(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1.0 : 1.0;
  const Mat3 R = svd.matrixV() * D * svd.matrixU().transpose();
  Rigid out = Rigid::Identity();
  out.linear() = R;
  out.translation() = ct - R * cs;
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

}  // namespace btr
