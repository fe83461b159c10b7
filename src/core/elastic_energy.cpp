#include "breast_tumour_registration/core/elastic_energy.h"

#include <string>

#include "breast_tumour_registration/core/errors.h"

namespace btr {

ElasticEnergy::ElasticEnergy(const TetMesh& rest, std::vector<StableNeoHookean> materials,
                             std::vector<int> material_of)
    : T_(rest.T), rest_(compute_rest_data(rest)), materials_(std::move(materials)),
      material_of_(std::move(material_of)) {
  if (materials_.empty()) throw InputError("ElasticEnergy: no material given");
  if (material_of_.empty()) material_of_.assign(T_.rows(), 0);
  if (static_cast<Eigen::Index>(material_of_.size()) != T_.rows())
    throw InputError("ElasticEnergy: material_of has " + std::to_string(material_of_.size()) + " entries for " +
                     std::to_string(T_.rows()) + " tetrahedra");
  for (int m : material_of_)
    if (m < 0 || m >= static_cast<int>(materials_.size()))
      throw InputError("ElasticEnergy: material index " + std::to_string(m) + " out of range");
}

double ElasticEnergy::element_value(const Points& x, Eigen::Index t) const {
  const Mat3 F = deformation_gradient(x, T_.row(t), rest_[t].Dm_inv);
  return rest_[t].volume * materials_[material_of_[t]].psi(F);
}

Vec12 ElasticEnergy::element_gradient(const Points& x, Eigen::Index t) const {
  const Mat3 F = deformation_gradient(x, T_.row(t), rest_[t].Dm_inv);
  const Mat3 P = materials_[material_of_[t]].pk1(F);
  // B^T vec(P): vertex k+1 gets column k of P Dm^-T, vertex 0 minus their sum.
  const Mat3 G = rest_[t].volume * P * rest_[t].Dm_inv.transpose();
  Vec12 g;
  g.segment<3>(3) = G.col(0);
  g.segment<3>(6) = G.col(1);
  g.segment<3>(9) = G.col(2);
  g.segment<3>(0) = -(G.col(0) + G.col(1) + G.col(2));
  return g;
}

Mat12 ElasticEnergy::element_hessian(const Points& x, Eigen::Index t, bool project_psd) const {
  const Mat3 F = deformation_gradient(x, T_.row(t), rest_[t].Dm_inv);
  const auto& mat = materials_[material_of_[t]];
  const Mat9 H9 = project_psd ? mat.clamped_hessian(F) : mat.hessian(F);
  // dF/dx = G^T (x) I3 with G (4x3) the shape-function gradients, so block (a,b) of
  // B^T H B is sum_jl G(a,j) G(b,l) H_jl (3x3 blocks of H9): a third of the dense flops.
  const Mat3& Dinv = rest_[t].Dm_inv;
  Eigen::Matrix<double, 4, 3> G;
  G.bottomRows<3>() = Dinv;
  G.row(0) = -Dinv.colwise().sum();
  Eigen::Matrix<double, 9, 12> HG;  // HG.block(3j, 3b) = sum_l G(b,l) H_jl
  for (int b = 0; b < 4; ++b)
    HG.middleCols<3>(3 * b) = G(b, 0) * H9.middleCols<3>(0) + G(b, 1) * H9.middleCols<3>(3) + G(b, 2) * H9.middleCols<3>(6);
  Mat12 K;
  for (int a = 0; a < 4; ++a)
    K.middleRows<3>(3 * a) = G(a, 0) * HG.middleRows<3>(0) + G(a, 1) * HG.middleRows<3>(3) + G(a, 2) * HG.middleRows<3>(6);
  return rest_[t].volume * K;
}

double ElasticEnergy::value(const Points& x) const {
  double e = 0;
#pragma omp parallel for reduction(+ : e) schedule(static)
  for (Eigen::Index t = 0; t < T_.rows(); ++t) e += element_value(x, t);
  return e;
}

void ElasticEnergy::add_gradient(const Points& x, Eigen::VectorXd& g) const {
  std::vector<Vec12> ge(T_.rows());
#pragma omp parallel for schedule(static)
  for (Eigen::Index t = 0; t < T_.rows(); ++t) ge[t] = element_gradient(x, t);
  for (Eigen::Index t = 0; t < T_.rows(); ++t)
    for (int a = 0; a < 4; ++a) g.segment<3>(3 * T_(t, a)) += ge[t].segment<3>(3 * a);
}

void ElasticEnergy::add_hessian(const Points& x, bool project_psd, HessianAssembler& H) const {
  const Eigen::Index nt = T_.rows();
  if (cached_for_ != H.id()) {
    offsets_.assign(16 * nt, -1);
    strides_.assign(4 * nt, 0);
    for (Eigen::Index t = 0; t < nt; ++t)
      for (int b = 0; b < 4; ++b) {
        if (!H.is_fixed(T_(t, b))) strides_[4 * t + b] = H.column_stride(T_(t, b));
        for (int a = 0; a < 4; ++a) offsets_[16 * t + 4 * b + a] = H.block_offset(T_(t, a), T_(t, b));
      }
    buffer_.resize(nt);
    cached_for_ = H.id();
  }
#pragma omp parallel for schedule(static)
  for (Eigen::Index t = 0; t < nt; ++t) buffer_[t] = element_hessian(x, t, project_psd);
  double* values = H.values();
  for (Eigen::Index t = 0; t < nt; ++t) {
    const Mat12& He = buffer_[t];
    for (int b = 0; b < 4; ++b) {
      const long stride = strides_[4 * t + b];
      for (int a = 0; a < 4; ++a) {
        const long off = offsets_[16 * t + 4 * b + a];
        if (off < 0) continue;
        double* v = values + off;
        for (int k = 0; k < 3; ++k)
          for (int r = 0; r < 3; ++r) v[k * stride + r] += He(3 * a + r, 3 * b + k);
      }
    }
  }
}

}  // namespace btr
