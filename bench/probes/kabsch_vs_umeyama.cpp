// Why Kabsch could become Eigen::umeyama without changing an answer: the hand-written fit
// (the SVD of the cross-covariance with the reflection excluded) against Eigen::umeyama
// without scaling, on 1000 noisy point sets. Measured 2026-12-02: largest entry difference
// 7.4e-15.  g++ -O2 -std=c++17 -I/usr/include/eigen3 bench/probes/kabsch_vs_umeyama.cpp -o /tmp/k && /tmp/k
#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <cstdio>
#include <random>
using P = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
Eigen::Matrix4d old_kabsch(const P& s, const P& t) {
  Eigen::Vector3d cs = s.colwise().mean().transpose(), ct = t.colwise().mean().transpose();
  Eigen::MatrixX3d S = s.rowwise() - cs.transpose(), T = t.rowwise() - ct.transpose();
  Eigen::Matrix3d C = S.transpose() * T;
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(C, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d D = Eigen::Matrix3d::Identity();
  D(2, 2) = (svd.matrixV() * svd.matrixU().transpose()).determinant() < 0 ? -1 : 1;
  Eigen::Matrix3d R = svd.matrixV() * D * svd.matrixU().transpose();
  Eigen::Matrix4d M = Eigen::Matrix4d::Identity(); M.topLeftCorner<3,3>() = R; M.topRightCorner<3,1>() = ct - R * cs; return M;
}
int main() {
  std::mt19937 g(1); std::normal_distribution<double> n(0, 0.05);
  double worst = 0;
  for (int k = 0; k < 1000; ++k) {
    int m = 3 + k % 20; P s(m, 3), t(m, 3);
    for (int i = 0; i < m; ++i) for (int j = 0; j < 3; ++j) s(i, j) = n(g);
    Eigen::Matrix3d R = Eigen::AngleAxisd(n(g) * 20, Eigen::Vector3d(n(g), n(g), n(g)).normalized()).toRotationMatrix();
    for (int i = 0; i < m; ++i) t.row(i) = (R * s.row(i).transpose()).transpose() + Eigen::RowVector3d(0.1, 0.2, 0.3) + Eigen::RowVector3d(n(g), n(g), n(g)) * 0.05;
    Eigen::Matrix4d a = old_kabsch(s, t), b = Eigen::umeyama(s.transpose(), t.transpose(), false);
    worst = std::max(worst, (a - b).cwiseAbs().maxCoeff());
  }
  std::printf("largest entry difference, hand Kabsch vs Eigen::umeyama, 1000 noisy sets of 3-22 points: %.3g\n", worst);
}
