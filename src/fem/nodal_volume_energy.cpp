#include "breast_tumour_registration/fem/nodal_volume_energy.h"

#include <algorithm>
#include <exception>
#include <string>
#include <utility>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/parallel_for.h"
#include "breast_tumour_registration/fem/determinant_eigensystem.h"
#include "breast_tumour_registration/fem/hessian_pattern.h"
#include "breast_tumour_registration/fem/material_assignment.h"
#include "breast_tumour_registration/fem/small_matrices.h"

namespace btr {

NodalVolumeEnergy::NodalVolumeEnergy(const TetMesh& rest, const std::vector<double>& lambda,
                                     std::vector<StableNeoHookean> shear, std::vector<int> material_of,
                                     const std::vector<double>& element_share)
    : T_(rest.T), rest_(compute_rest_data(rest)), shear_(std::move(shear)), material_of_(std::move(material_of)) {
  if (static_cast<Eigen::Index>(lambda.size()) != T_.rows())
    throw InputError("NodalVolumeEnergy: " + std::to_string(lambda.size()) + " volume stiffnesses for " +
                     std::to_string(T_.rows()) + " tetrahedra");
  for (size_t k = 0; k < shear_.size(); ++k)
    if (shear_[k].lambda() != 0)
      throw InputError("NodalVolumeEnergy: material " + std::to_string(k) +
                       " has a volume term of its own (give its shear_part(): the volume term is this term's)");
  if (!element_share.empty() && static_cast<Eigen::Index>(element_share.size()) != T_.rows())
    throw InputError("NodalVolumeEnergy: " + std::to_string(element_share.size()) + " element shares for " +
                     std::to_string(T_.rows()) + " tetrahedra");
  if (shear_.empty() && !material_of_.empty())
    throw InputError("NodalVolumeEnergy: a material per tetrahedron was given without the materials' shear parts to index");
  if (!shear_.empty()) material_of_ = checked_material_of(std::move(material_of_), shear_.size(), T_.rows(), "NodalVolumeEnergy");
  const Eigen::Index nv = rest.V.rows();
  Vn_ = Eigen::VectorXd::Zero(nv);
  lambda_n_ = Eigen::VectorXd::Zero(nv);
  patches_.assign(nv, {});
  tets_of_.assign(nv, {});
  if (!element_share.empty()) kappa_ = Eigen::VectorXd::Zero(T_.rows());
  for (Eigen::Index t = 0; t < T_.rows(); ++t) {
    if (!(lambda[t] >= 0) || !std::isfinite(lambda[t]))
      throw InputError("NodalVolumeEnergy: volume stiffness of tetrahedron " + std::to_string(t) + " is not >= 0");
    if (!element_share.empty()) {
      if (!(element_share[t] >= 0 && element_share[t] <= lambda[t]))
        throw InputError("NodalVolumeEnergy: element share of tetrahedron " + std::to_string(t) +
                         " is not in [0, its volume stiffness]");
      kappa_[t] = element_share[t];
    }
    const double averaged = kappa_.size() > 0 ? lambda[t] - kappa_[t] : lambda[t];
    for (int a = 0; a < 4; ++a) {
      const int n = T_(t, a);
      Vn_[n] += rest_[t].volume / 4;
      lambda_n_[n] += rest_[t].volume / 4 * averaged;
      tets_of_[n].push_back(static_cast<int>(t));
      for (int b = 0; b < 4; ++b) patches_[n].push_back(T_(t, b));
    }
  }
  for (Eigen::Index n = 0; n < nv; ++n) {
    if (Vn_[n] > 0) lambda_n_[n] /= Vn_[n];
    auto& p = patches_[n];
    std::sort(p.begin(), p.end());
    p.erase(std::unique(p.begin(), p.end()), p.end());
  }
  column_start_.assign(nv + 1, 0);
  for (const auto& p : patches_)
    for (int j : p) ++column_start_[j + 1];
  for (Eigen::Index j = 0; j < nv; ++j) column_start_[j + 1] += column_start_[j];
  column_patches_.resize(column_start_.back());
  std::vector<size_t> next(column_start_.begin(), column_start_.end() - 1);
  for (Eigen::Index n = 0; n < nv; ++n)
    for (size_t jj = 0; jj < patches_[n].size(); ++jj)
      column_patches_[next[patches_[n][jj]]++] = {static_cast<int>(n), static_cast<int>(jj)};
}

Eigen::VectorXd NodalVolumeEnergy::element_volumes(const Points& x) const {
  Eigen::VectorXd v(T_.rows());
#pragma omp parallel for schedule(static)
  for (Eigen::Index t = 0; t < T_.rows(); ++t)
    v[t] = rest_[t].volume * deformation_gradient(x, T_.row(t), rest_[t].Dm_inv).determinant();
  return v;
}

Eigen::VectorXd NodalVolumeEnergy::nodal_volume_ratios(const Points& x) const {
  const Eigen::VectorXd v = element_volumes(x);
  Eigen::VectorXd J = Eigen::VectorXd::Zero(Vn_.size());
  for (Eigen::Index t = 0; t < T_.rows(); ++t)
    for (int a = 0; a < 4; ++a) J[T_(t, a)] += v[t] / 4;
  for (Eigen::Index n = 0; n < J.size(); ++n) J[n] = Vn_[n] > 0 ? J[n] / Vn_[n] : 0.0;
  return J;
}

double NodalVolumeEnergy::element_pressure(const Eigen::VectorXd& J, Eigen::Index t, double Jt) const {
  double s = 0;
  for (int a = 0; a < 4; ++a) s += lambda_n_[T_(t, a)] * (J[T_(t, a)] - 1) / 4;
  if (kappa_.size() > 0) s += kappa_[t] * (Jt - 1);
  return s;
}

double NodalVolumeEnergy::value(const Points& x) const {
  const Eigen::VectorXd J = nodal_volume_ratios(x);
  double e = 0;
  for (Eigen::Index n = 0; n < J.size(); ++n)
    if (Vn_[n] > 0) e += 0.5 * lambda_n_[n] * Vn_[n] * (J[n] - 1) * (J[n] - 1);
  // The per-element parts (the element share and the shear part), on one F per tetrahedron.
  const bool share = kappa_.size() > 0, shear = !shear_.empty();
  if (share || shear) {
    double per_element = 0;
#pragma omp parallel for reduction(+ : per_element) schedule(static)
    for (Eigen::Index t = 0; t < T_.rows(); ++t) {
      const Mat3 F = deformation_gradient(x, T_.row(t), rest_[t].Dm_inv);
      double psi = shear ? shear_[material_of_[t]].psi(F) : 0.0;
      if (share) {
        const double dJ = F.determinant() - 1;
        psi += 0.5 * kappa_[t] * dJ * dJ;
      }
      per_element += rest_[t].volume * psi;
    }
    e += per_element;
  }
  return e;
}

void NodalVolumeEnergy::add_gradient(const Points& x, Eigen::VectorXd& g) const {
  // dE/dx = sum_t s_t dv_t/dx, s_t = sum_{n in t} lambda_n (Jbar_n - 1) / 4.
  // With the shear part: + V_t P_shear(F) per element.
  const Eigen::VectorXd J = nodal_volume_ratios(x);
  const Eigen::Index nt = T_.rows();
  grad_.resize(nt);
#pragma omp parallel for schedule(static)
  for (Eigen::Index t = 0; t < nt; ++t) {
    const Mat3 F = deformation_gradient(x, T_.row(t), rest_[t].Dm_inv);
    const Vec9 dJ = determinant_gradient(F);
    Mat3 P = element_pressure(J, t, F.determinant()) * Eigen::Map<const Mat3>(dJ.data());
    if (!shear_.empty()) P += shear_[material_of_[t]].pk1(F);
    grad_[t] = tet_gradient_from_stress(P, rest_[t].Dm_inv, rest_[t].volume);
  }
  for (Eigen::Index t = 0; t < nt; ++t)
    for (int a = 0; a < 4; ++a) g.segment<3>(3 * T_(t, a)) += grad_[t].segment<3>(3 * a);
}

void NodalVolumeEnergy::build_scatter(const HessianAssembler& H) const {
  tet_scatter_.build(H, T_);
  patch_offset_.assign(patches_.size() + 1, 0);
  patch_stride_.assign(patches_.size() + 1, 0);
  for (size_t n = 0; n < patches_.size(); ++n) {
    patch_offset_[n + 1] = patch_offset_[n] + patches_[n].size() * patches_[n].size();
    patch_stride_[n + 1] = patch_stride_[n] + patches_[n].size();
  }
  patch_offsets_.assign(patch_offset_.back(), -1);
  const Eigen::Index nv = static_cast<Eigen::Index>(patches_.size());
  // block_offset throws for a pair outside the pattern (an assembler built without this term's
  // cliques).
  if (const std::exception_ptr failed = parallel_for_capturing(nv, [&](Eigen::Index n) {
        const auto& p = patches_[n];
        for (size_t j = 0; j < p.size(); ++j)
          for (size_t i = 0; i < p.size(); ++i) patch_offsets_[patch_offset_[n] + j * p.size() + i] = H.block_offset(p[i], p[j]);
      })) {
    tet_scatter_ = TetScatter();  // not current for H
    std::rethrow_exception(failed);
  }
}

void NodalVolumeEnergy::add_hessian(const Points& x, bool project_psd, HessianAssembler& H) const {
  if (!tet_scatter_.built_for(H)) build_scatter(H);
  const Eigen::VectorXd J = nodal_volume_ratios(x);
  const Eigen::Index nt = T_.rows();
  // dv_t/dx per tetrahedron (12-vectors), for the rank-one patch terms.
  dv_.resize(nt);
  ke_.resize(nt);
  std::vector<Vec12>& dv = dv_;
  std::vector<Mat12>& Ke = ke_;
#pragma omp parallel for schedule(static)
  for (Eigen::Index t = 0; t < nt; ++t) {
    const Mat3 F = deformation_gradient(x, T_.row(t), rest_[t].Dm_inv);
    const Vec9 dJ = determinant_gradient(F);
    dv[t] = tet_gradient_from_stress(Eigen::Map<const Mat3>(dJ.data()), rest_[t].Dm_inv, rest_[t].volume);
    // s d2J/dF2, or with the shear part mu I + (s - mu) d2J/dF2.
    const double mu = shear_.empty() ? 0.0 : shear_[material_of_[t]].mu(),
                 c = element_pressure(J, t, F.determinant()) - mu;
    const Mat9 H9 = project_psd ? projected_determinant_hessian(F, c, mu)
                                : Mat9(c * determinant_hessian(F) + mu * Mat9::Identity());
    Ke[t] = tet_hessian_from_stress_hessian(H9, rest_[t].Dm_inv, rest_[t].volume);
    // The element share's rank-one part, kappa_t V_t dJ dJ^T = kappa_t / V_t dv dv^T (PSD).
    if (kappa_.size() > 0) Ke[t] += kappa_[t] / rest_[t].volume * dv[t] * dv[t].transpose();
  }
  for (Eigen::Index t = 0; t < nt; ++t) tet_scatter_.add(H, t, Ke[t]);
  double* values = H.values();
  // sum_n lambda_n / V_n a_n a_n^T, a_n = sum_{t at n} dv_t/dx / 4 over the patch of n: first
  // every a_n (per vertex, in parallel), then the blocks column by column (column_patches_).
  const Eigen::Index nv = static_cast<Eigen::Index>(patches_.size());
  std::vector<Vec3>& a = a_;
  a.assign(patch_stride_.back(), Vec3::Zero());
#pragma omp parallel for schedule(static)
  for (Eigen::Index n = 0; n < nv; ++n) {
    const auto& p = patches_[n];
    Vec3* an = a.data() + patch_stride_[n];
    for (int t : tets_of_[n])
      for (int k = 0; k < 4; ++k) {
        const size_t i = std::lower_bound(p.begin(), p.end(), T_(t, k)) - p.begin();
        an[i] += dv[t].segment<3>(3 * k) / 4;
      }
  }
#pragma omp parallel for schedule(dynamic, 32)
  for (Eigen::Index j = 0; j < nv; ++j) {
    if (H.is_fixed(static_cast<int>(j))) continue;
    const long stride = H.column_stride(static_cast<int>(j));
    for (size_t e = column_start_[j]; e < column_start_[j + 1]; ++e) {
      const auto [n, jj] = column_patches_[e];
      if (!(Vn_[n] > 0) || lambda_n_[n] == 0) continue;
      const size_t np = patches_[n].size();
      const Vec3* an = a.data() + patch_stride_[n];
      const Vec3 aj = lambda_n_[n] / Vn_[n] * an[jj];
      const long* offs = patch_offsets_.data() + patch_offset_[n] + jj * np;
      for (size_t i = 0; i < np; ++i) {
        const long off = offs[i];
        if (off < 0) continue;
        for (int k = 0; k < 3; ++k)
          for (int r = 0; r < 3; ++r) values[off + k * stride + r] += an[i][r] * aj[k];
      }
    }
  }
}

}  // namespace btr
