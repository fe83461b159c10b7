#include "breast_tumour_registration/fem/quadratic_elastic_energy.h"

#include <algorithm>
#include <string>
#include <utility>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/fem/determinant_eigensystem.h"
#include "breast_tumour_registration/fem/material_assignment.h"
#include "breast_tumour_registration/fem/small_matrices.h"
#include "breast_tumour_registration/fem/tet_kinematics.h"

namespace btr {

QuadraticElasticEnergy::QuadraticElasticEnergy(const QuadraticTetMesh& mesh, const Points& rest_corners,
                                               std::vector<StableNeoHookean> materials, std::vector<int> material_of,
                                               int quadrature_degree, QuadraticVolume volume)
    : T_(mesh.T),
      nodes_(mesh.nodes()),
      materials_(std::move(materials)),
      material_of_(checked_material_of(std::move(material_of), materials_.size(), mesh.T.rows(), "QuadraticElasticEnergy")),
      rule_(tet_quadrature(quadrature_degree)),
      volume_form_(volume) {
  for (const auto& m : materials_) {  // SNH lambda = lambda_L + mu
    local_.push_back(StableNeoHookean::from_lame(m.mu(), 0.0));
    lambda_lame_.push_back(m.lambda() - m.mu());
  }
  if (rest_corners.rows() != mesh.corners)
    throw InputError("QuadraticElasticEnergy: " + std::to_string(rest_corners.rows()) + " rest positions for " +
                     std::to_string(mesh.corners) + " vertices");
  for (const auto& q : rule_) shape_derivatives_.push_back(quadratic_shape_barycentric_derivatives(q.barycentric));
  // The rest elements are straight-sided: the corner tetrahedra's rest data (InputError on a
  // degenerate or inverted one) give the volumes and the barycentric gradients.
  const std::vector<TetRestData> rest = compute_rest_data(TetMesh{rest_corners, T_.leftCols<4>()});
  barycentric_gradients_.resize(T_.rows());
  volume_.resize(T_.rows());
  for (Eigen::Index t = 0; t < T_.rows(); ++t) {
    volume_[t] = rest[t].volume;
    const Mat3& Dinv = rest[t].Dm_inv;  // rows: gradients of barycentric coordinates 1..3
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

double QuadraticElasticEnergy::mean_volume_change(const Eigen::Matrix<double, 3, 10>& X, Eigen::Index t) const {
  double J = 0;
  for (size_t q = 0; q < rule_.size(); ++q) J += rule_[q].weight * (X * shape_gradients(t, q)).determinant();
  return J;
}

double QuadraticElasticEnergy::element_value(const Points& x, Eigen::Index t) const {
  const Eigen::Matrix<double, 3, 10> X = element_nodes(x, T_, t);
  const bool mean = volume_form_ == QuadraticVolume::ElementMean;
  const StableNeoHookean& m = mean ? local_[material_of_[t]] : materials_[material_of_[t]];
  double e = 0;
  for (size_t q = 0; q < rule_.size(); ++q) e += rule_[q].weight * m.psi(X * shape_gradients(t, q));
  if (mean) {
    const double Jbar = mean_volume_change(X, t);
    e += 0.5 * lambda_lame_[material_of_[t]] * (Jbar - 1) * (Jbar - 1);
  }
  return volume_[t] * e;
}

Vec30 QuadraticElasticEnergy::element_gradient(const Points& x, Eigen::Index t) const {
  const Eigen::Matrix<double, 3, 10> X = element_nodes(x, T_, t);
  const bool mean = volume_form_ == QuadraticVolume::ElementMean;
  const StableNeoHookean& m = mean ? local_[material_of_[t]] : materials_[material_of_[t]];
  const double pressure = mean ? lambda_lame_[material_of_[t]] * (mean_volume_change(X, t) - 1) : 0.0;
  Eigen::Matrix<double, 3, 10> G = Eigen::Matrix<double, 3, 10>::Zero();
  for (size_t q = 0; q < rule_.size(); ++q) {
    const Eigen::Matrix<double, 10, 3> dN = shape_gradients(t, q);
    const Mat3 F = X * dN;
    Mat3 P = m.pk1(F);
    if (mean) P += pressure * Eigen::Map<const Mat3>(determinant_gradient(F).data());
    G.noalias() += rule_[q].weight * P * dN.transpose();
  }
  G *= volume_[t];
  return Eigen::Map<const Vec30>(G.data());
}

Mat30 QuadraticElasticEnergy::element_hessian(const Points& x, Eigen::Index t, bool project_psd) const {
  const Eigen::Matrix<double, 3, 10> X = element_nodes(x, T_, t);
  const bool mean = volume_form_ == QuadraticVolume::ElementMean;
  const StableNeoHookean& m = mean ? local_[material_of_[t]] : materials_[material_of_[t]];
  const double pressure = mean ? lambda_lame_[material_of_[t]] * (mean_volume_change(X, t) - 1) : 0.0;
  Mat30 K = Mat30::Zero();
  Vec30 dJbar = Vec30::Zero();
  for (size_t q = 0; q < rule_.size(); ++q) {
    const Eigen::Matrix<double, 10, 3> dN = shape_gradients(t, q);
    const Mat3 F = X * dN;
    Mat9 H9;
    if (!mean) {
      H9 = project_psd ? m.clamped_hessian(F) : m.hessian(F);
    } else {
      // The local part mu I + mu g g^T + (mu (J - 1) - mu) H_J plus the element's pressure on H_J;
      // projected, the g g^T part is PSD already and the rest has a closed-form eigensystem.
      const Vec9 g = determinant_gradient(F);
      const double mu = m.mu(), s = mu * (F.determinant() - 1) - mu + pressure;
      H9 = project_psd ? projected_determinant_hessian(F, s, mu) : Mat9(mu * Mat9::Identity() + s * determinant_hessian(F));
      H9.noalias() += mu * g * g.transpose();
      // dJ/dx_a = (cof F) grad N_a
      for (int a = 0; a < 10; ++a)
        dJbar.segment<3>(3 * a) += rule_[q].weight * Eigen::Map<const Mat3>(g.data()) * dN.row(a).transpose();
    }
    // B^T H9 B with B = d vec(F) / dx (vec(F)[i + 3k] = sum_a x_a[i] dN(a, k)), B's sparsity used:
    // C = H9 B (9 x 30), then K += B^T C, a third of the dense products' flops.
    const double wv = rule_[q].weight * volume_[t];
    Eigen::Matrix<double, 9, 30> C;
    for (int b = 0; b < 10; ++b)
      C.middleCols<3>(3 * b) = dN(b, 0) * H9.middleCols<3>(0) + dN(b, 1) * H9.middleCols<3>(3) + dN(b, 2) * H9.middleCols<3>(6);
    for (int a = 0; a < 10; ++a)
      K.middleRows<3>(3 * a).noalias() +=
          wv * (dN(a, 0) * C.middleRows<3>(0) + dN(a, 1) * C.middleRows<3>(3) + dN(a, 2) * C.middleRows<3>(6));
  }
  if (mean) K.noalias() += (lambda_lame_[material_of_[t]] * volume_[t]) * dJbar * dJbar.transpose();
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
  if (!scatter_.built_for(H)) scatter_.build(H, T_);
  // In chunks, so the element matrices in flight stay a few megabytes.
  const Eigen::Index chunk = 1024;
  std::vector<Mat30> K(static_cast<size_t>(std::min(chunk, nt)));
  for (Eigen::Index t0 = 0; t0 < nt; t0 += chunk) {
    const Eigen::Index n = std::min(chunk, nt - t0);
#pragma omp parallel for schedule(static)
    for (Eigen::Index i = 0; i < n; ++i) K[i] = element_hessian(x, t0 + i, project_psd);
    for (Eigen::Index i = 0; i < n; ++i) scatter_.add(H, t0 + i, K[i]);
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
