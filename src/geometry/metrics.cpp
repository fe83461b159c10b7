#include "breast_tumour_registration/geometry/metrics.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/geometry/closest_point.h"

namespace btr {

double enclosed_volume(const SurfaceMesh& s) {
  double v = 0;
  for (Eigen::Index f = 0; f < s.F.rows(); ++f)
    v += Vec3(s.V.row(s.F(f, 0))).dot(Vec3(s.V.row(s.F(f, 1))).cross(Vec3(s.V.row(s.F(f, 2))))) / 6.0;
  return v;
}

Vec3 volume_centroid(const SurfaceMesh& s) {
  double vol = 0;
  Vec3 c = Vec3::Zero();
  for (Eigen::Index f = 0; f < s.F.rows(); ++f) {
    const Vec3 a = s.V.row(s.F(f, 0)), b = s.V.row(s.F(f, 1)), d = s.V.row(s.F(f, 2));
    const double v = a.dot(b.cross(d)) / 6.0;
    vol += v;
    c += v * (a + b + d) / 4.0;
  }
  if (!(std::abs(vol) > 0)) throw InputError("volume centroid of a surface with zero volume (open or flat?)");
  return c / vol;
}

Eigen::MatrixXd volume_centroid_jacobian(const SurfaceMesh& s) {
  // c = M / V with V = sum_f V_f, M = sum_f V_f S_f / 4, V_f = a.(b x d) / 6, S_f = a + b + d:
  // dc/dp = (dM/dp - c dV/dp) / V, dV_f/da = (b x d) / 6 (cyclic), dS_f/da = I.
  const Vec3 c = volume_centroid(s);
  const double vol = enclosed_volume(s);
  Eigen::MatrixXd J = Eigen::MatrixXd::Zero(3, 3 * s.V.rows());
  for (Eigen::Index f = 0; f < s.F.rows(); ++f) {
    const int idx[3] = {s.F(f, 0), s.F(f, 1), s.F(f, 2)};
    const Vec3 p[3] = {s.V.row(idx[0]), s.V.row(idx[1]), s.V.row(idx[2])};
    const double vf = p[0].dot(p[1].cross(p[2])) / 6.0;
    const Vec3 S = p[0] + p[1] + p[2];
    for (int i = 0; i < 3; ++i) {
      const Vec3 dv = p[(i + 1) % 3].cross(p[(i + 2) % 3]) / 6.0;  // dV_f / dp_i
      // dM/dp_i = (S - 4 c) dv^T / 4 + V_f / 4 I (the -c dV/dp term folded in)
      J.middleCols<3>(3 * idx[i]) += ((S / 4.0 - c) * dv.transpose() + (vf / 4.0) * Mat3::Identity()) / vol;
    }
  }
  return J;
}

double principal_axis_ratio(const SurfaceMesh& s) {
  // Second moment of the volume by summing signed tetrahedra (origin, a, b, c):
  // int x x^T dV = V/20 (sum_i p_i p_i^T + S S^T), S = sum_i p_i (origin contributes 0).
  Mat3 M = Mat3::Zero();
  double vol = 0;
  Vec3 first = Vec3::Zero();
  for (Eigen::Index f = 0; f < s.F.rows(); ++f) {
    const Vec3 a = s.V.row(s.F(f, 0)), b = s.V.row(s.F(f, 1)), c = s.V.row(s.F(f, 2));
    const double v = a.dot(b.cross(c)) / 6.0;
    const Vec3 S = a + b + c;
    M += v / 20.0 * (a * a.transpose() + b * b.transpose() + c * c.transpose() + S * S.transpose());
    vol += v;
    first += v * S / 4.0;
  }
  if (!(std::abs(vol) > 0)) throw InputError("principal axes of a surface with zero volume");
  const Vec3 centre = first / vol;
  const Mat3 C = M / vol - centre * centre.transpose();
  const Vec3 ev = Eigen::SelfAdjointEigenSolver<Mat3>(C).eigenvalues();
  return std::sqrt(std::max(ev[0], 0.0) / ev[2]);
}

std::vector<double> point_to_surface_distances(const Points& P, const SurfaceMesh& s) {
  const SurfaceClosestPoint cp(s.V, s.F);
  std::vector<double> d(P.rows());
  for (Eigen::Index i = 0; i < P.rows(); ++i) d[i] = cp.query(P.row(i).transpose()).distance;
  return d;
}

double hausdorff_distance(const SurfaceMesh& a, const SurfaceMesh& b) {
  const auto ab = point_to_surface_distances(a.V, b), ba = point_to_surface_distances(b.V, a);
  return std::max(*std::max_element(ab.begin(), ab.end()), *std::max_element(ba.begin(), ba.end()));
}

DistanceStats distance_stats(const std::vector<double>& d) {
  DistanceStats s;
  if (d.empty()) return s;
  double sum = 0, sq = 0;
  for (double x : d) {
    sum += x;
    sq += x * x;
    s.max = std::max(s.max, x);
  }
  s.mean = sum / d.size();
  s.rms = std::sqrt(sq / d.size());
  return s;
}

}  // namespace btr
