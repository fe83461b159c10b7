#include "breast_tumour_registration/fem/quadratic_elastic_energy.h"

#include <algorithm>
#include <string>
#include <utility>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/parallel_for.h"
#include "breast_tumour_registration/fem/material_assignment.h"

namespace btr {

QuadraticElasticEnergy::QuadraticElasticEnergy(const QuadraticTetMesh& mesh, const Points& rest_corners,
                                               std::vector<StableNeoHookean> materials, std::vector<int> material_of,
                                               int quadrature_degree)
    : T_(mesh.T),
      nodes_(mesh.nodes()),
      materials_(std::move(materials)),
      material_of_(checked_material_of(std::move(material_of), materials_.size(), mesh.T.rows(), "QuadraticElasticEnergy")),
      rule_(tet_quadrature(quadrature_degree)) {
  if (rest_corners.rows() != mesh.corners)
    throw InputError("QuadraticElasticEnergy: " + std::to_string(rest_corners.rows()) + " rest positions for " +
                     std::to_string(mesh.corners) + " vertices");
  for (const auto& q : rule_) shape_derivatives_.push_back(quadratic_shape_barycentric_derivatives(q.barycentric));
  barycentric_gradients_.resize(T_.rows());
  volume_.resize(T_.rows());
  for (Eigen::Index t = 0; t < T_.rows(); ++t) {
    Mat3 Dm;
    for (int k = 0; k < 3; ++k) Dm.col(k) = (rest_corners.row(T_(t, k + 1)) - rest_corners.row(T_(t, 0))).transpose();
    const double det = Dm.determinant();
    if (!(det > 0)) throw InputError("QuadraticElasticEnergy: rest tetrahedron " + std::to_string(t) + " is degenerate or inverted");
    volume_[t] = det / 6;
    const Mat3 Dinv = Dm.inverse();  // rows: gradients of barycentric coordinates 1..3
    barycentric_gradients_[t].row(0) = -Dinv.colwise().sum();
    barycentric_gradients_[t].bottomRows<3>() = Dinv;
  }
}

Eigen::Matrix<double, 10, 3> QuadraticElasticEnergy::shape_gradients(Eigen::Index t, size_t q) const {
  return shape_derivatives_[q] * barycentric_gradients_[t];
}

namespace {
// The 10 node positions of element t as a 3 x 10 matrix.
Eigen::Matrix<double, 3, 10> element_nodes(const Points& x, const QuadraticTets& T, Eigen::Index t) {
  Eigen::Matrix<double, 3, 10> X;
  for (int a = 0; a < 10; ++a) X.col(a) = x.row(T(t, a)).transpose();
  return X;
}
}  // namespace

double QuadraticElasticEnergy::element_value(const Points& x, Eigen::Index t) const {
  const Eigen::Matrix<double, 3, 10> X = element_nodes(x, T_, t);
  const StableNeoHookean& m = materials_[material_of_[t]];
  double e = 0;
  for (size_t q = 0; q < rule_.size(); ++q) e += rule_[q].weight * m.psi(X * shape_gradients(t, q));
  return volume_[t] * e;
}

Vec30 QuadraticElasticEnergy::element_gradient(const Points& x, Eigen::Index t) const {
  const Eigen::Matrix<double, 3, 10> X = element_nodes(x, T_, t);
  const StableNeoHookean& m = materials_[material_of_[t]];
  Eigen::Matrix<double, 3, 10> G = Eigen::Matrix<double, 3, 10>::Zero();
  for (size_t q = 0; q < rule_.size(); ++q) {
    const Eigen::Matrix<double, 10, 3> dN = shape_gradients(t, q);
    G.noalias() += rule_[q].weight * m.pk1(X * dN) * dN.transpose();
  }
  G *= volume_[t];
  return Eigen::Map<const Vec30>(G.data());
}

Mat30 QuadraticElasticEnergy::element_hessian(const Points& x, Eigen::Index t, bool project_psd) const {
  const Eigen::Matrix<double, 3, 10> X = element_nodes(x, T_, t);
  const StableNeoHookean& m = materials_[material_of_[t]];
  Mat30 K = Mat30::Zero();
  Eigen::Matrix<double, 9, 30> B;
  for (size_t q = 0; q < rule_.size(); ++q) {
    const Eigen::Matrix<double, 10, 3> dN = shape_gradients(t, q);
    const Mat3 F = X * dN;
    // d vec(F) / d x: vec(F)[i + 3k] = sum_a x_a[i] dN(a, k).
    B.setZero();
    for (int a = 0; a < 10; ++a)
      for (int k = 0; k < 3; ++k)
        for (int i = 0; i < 3; ++i) B(i + 3 * k, 3 * a + i) = dN(a, k);
    const Mat9 H9 = project_psd ? m.clamped_hessian(F) : m.hessian(F);
    K.noalias() += (rule_[q].weight * volume_[t]) * (B.transpose() * H9 * B);
  }
  return K;
}

double QuadraticElasticEnergy::value(const Points& x) const {
  double e = 0;
#pragma omp parallel for reduction(+ : e) schedule(static)
  for (Eigen::Index t = 0; t < T_.rows(); ++t) e += element_value(x, t);
  return e;
}

void QuadraticElasticEnergy::add_gradient(const Points& x, Eigen::VectorXd& g) const {
  std::vector<Vec30> ge(T_.rows());
#pragma omp parallel for schedule(static)
  for (Eigen::Index t = 0; t < T_.rows(); ++t) ge[t] = element_gradient(x, t);
  for (Eigen::Index t = 0; t < T_.rows(); ++t)
    for (int a = 0; a < 10; ++a) g.segment<3>(3 * T_(t, a)) += ge[t].segment<3>(3 * a);
}

std::vector<std::vector<int>> QuadraticElasticEnergy::hessian_cliques() const {
  std::vector<std::vector<int>> c(T_.rows());
  for (Eigen::Index t = 0; t < T_.rows(); ++t) c[t].assign(T_.row(t).data(), T_.row(t).data() + 10);
  return c;
}

void QuadraticElasticEnergy::add_hessian(const Points& x, bool project_psd, HessianAssembler& H) const {
  const Eigen::Index nt = T_.rows();
  if (scatter_for_ != H.id()) {
    offsets_.assign(100 * nt, -1);
    strides_.assign(10 * nt, 0);
    if (const std::exception_ptr failed = parallel_for_capturing(nt, [&](Eigen::Index t) {
          for (int b = 0; b < 10; ++b) {
            if (!H.is_fixed(T_(t, b))) strides_[10 * t + b] = H.column_stride(T_(t, b));
            for (int a = 0; a < 10; ++a) offsets_[100 * t + 10 * b + a] = H.block_offset(T_(t, a), T_(t, b));
          }
        })) {
      scatter_for_ = 0;
      std::rethrow_exception(failed);
    }
    scatter_for_ = H.id();
  }
  // In chunks, so the element matrices in flight stay a few megabytes.
  const Eigen::Index chunk = 1024;
  std::vector<Mat30> K(static_cast<size_t>(std::min(chunk, nt)));
  double* values = H.values();
  for (Eigen::Index t0 = 0; t0 < nt; t0 += chunk) {
    const Eigen::Index n = std::min(chunk, nt - t0);
#pragma omp parallel for schedule(static)
    for (Eigen::Index i = 0; i < n; ++i) K[i] = element_hessian(x, t0 + i, project_psd);
    for (Eigen::Index i = 0; i < n; ++i) {
      const Eigen::Index t = t0 + i;
      for (int b = 0; b < 10; ++b) {
        const long stride = strides_[10 * t + b];
        for (int a = 0; a < 10; ++a) {
          const long off = offsets_[100 * t + 10 * b + a];
          if (off < 0) continue;
          double* v = values + off;
          for (int k = 0; k < 3; ++k)
            for (int r = 0; r < 3; ++r) v[k * stride + r] += K[i](3 * a + r, 3 * b + k);
        }
      }
    }
  }
}

Eigen::VectorXd QuadraticElasticEnergy::consistent_masses(double density) const {
  Eigen::VectorXd m = Eigen::VectorXd::Zero(nodes_);
  for (Eigen::Index t = 0; t < T_.rows(); ++t)
    for (const auto& q : rule_) {
      const Eigen::Matrix<double, 10, 1> N = quadratic_shape(q.barycentric);
      for (int a = 0; a < 10; ++a) m[T_(t, a)] += density * volume_[t] * q.weight * N[a];
    }
  return m;
}

}  // namespace btr
