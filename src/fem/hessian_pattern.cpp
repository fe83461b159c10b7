#include "breast_tumour_registration/fem/hessian_pattern.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <stdexcept>
#include <string>

#include "breast_tumour_registration/base/parallel_for.h"

namespace btr {

HessianAssembler::HessianAssembler(int nv, const Tetrahedra& T, const std::vector<bool>& fixed,
                                   const std::vector<std::vector<int>>& extra_cliques) {
  static std::atomic<unsigned long> next_id{1};
  id_ = next_id++;
  free_index_.assign(nv, -1);
  for (int v = 0; v < nv; ++v)
    if (fixed.empty() || !fixed[v]) {
      free_index_[v] = num_free_++;
      free_vertex_.push_back(v);
    }
  nbrs_.assign(num_free_, {});
  for (int f = 0; f < num_free_; ++f) nbrs_[f].push_back(f);
  auto couple = [&](const int* vs, int n) {
    for (int a = 0; a < n; ++a) {
      const int fa = free_index_[vs[a]];
      if (fa < 0) continue;
      for (int b = 0; b < n; ++b) {
        const int fb = free_index_[vs[b]];
        if (fb >= 0 && fb != fa) nbrs_[fa].push_back(fb);
      }
    }
  };
  for (Eigen::Index t = 0; t < T.rows(); ++t) couple(T.row(t).data(), 4);
  for (const auto& c : extra_cliques) couple(c.data(), static_cast<int>(c.size()));
  long nnz = 0;
  for (auto& n : nbrs_) {
    std::sort(n.begin(), n.end());
    n.erase(std::unique(n.begin(), n.end()), n.end());
    nnz += 9 * static_cast<long>(n.size());
  }
  // Build the compressed column storage directly: column 3f+k holds rows 3n+a for n in nbrs[f].
  const int ndof = 3 * num_free_;
  H_.resize(ndof, ndof);
  H_.resizeNonZeros(nnz);
  auto* outer = H_.outerIndexPtr();
  auto* inner = H_.innerIndexPtr();
  long p = 0;
  for (int f = 0; f < num_free_; ++f)
    for (int k = 0; k < 3; ++k) {
      outer[3 * f + k] = static_cast<int>(p);
      for (int n : nbrs_[f])
        for (int a = 0; a < 3; ++a) inner[p++] = 3 * n + a;
    }
  outer[ndof] = static_cast<int>(p);
  set_zero();
}

void HessianAssembler::set_zero() { std::fill(H_.valuePtr(), H_.valuePtr() + H_.nonZeros(), 0.0); }

long HessianAssembler::block_offset(int vi, int vj) const {
  const int fi = free_index_[vi], fj = free_index_[vj];
  if (fi < 0 || fj < 0) return -1;
  const auto& n = nbrs_[fj];
  const auto it = std::lower_bound(n.begin(), n.end(), fi);
  if (it == n.end() || *it != fi)
    throw std::logic_error("HessianAssembler: vertices " + std::to_string(vi) + " and " + std::to_string(vj) +
                           " are not coupled in the sparsity pattern");
  return H_.outerIndexPtr()[3 * fj] + 3 * (it - n.begin());
}

void HessianAssembler::add_block(int vi, int vj, const Mat3& B) {
  const long off = block_offset(vi, vj);
  if (off < 0) return;
  const long stride = column_stride(vj);
  double* v = H_.valuePtr() + off;
  for (int k = 0; k < 3; ++k)
    for (int a = 0; a < 3; ++a) v[k * stride + a] += B(a, k);
}

Eigen::VectorXd HessianAssembler::gather(const Eigen::VectorXd& full) const {
  Eigen::VectorXd r(3 * num_free_);
  for (int f = 0; f < num_free_; ++f) r.segment<3>(3 * f) = full.segment<3>(3 * free_vertex_[f]);
  return r;
}

void HessianAssembler::scatter_add(const Eigen::VectorXd& reduced, double scale, Eigen::VectorXd& full) const {
  for (int f = 0; f < num_free_; ++f) full.segment<3>(3 * free_vertex_[f]) += scale * reduced.segment<3>(3 * f);
}

template <int N>
void ElementScatter<N>::build(const HessianAssembler& H, const Elements& T) {
  offsets_.assign(static_cast<size_t>(N * N * T.rows()), -1);
  strides_.assign(static_cast<size_t>(N * T.rows()), 0);
  // In parallel (an energy whose material changes is rebuilt with its maps: 46 times in one
  // nodal-form registration with E estimated); block_offset throws for a pair outside the pattern.
  if (const std::exception_ptr failed = parallel_for_capturing(T.rows(), [&](Eigen::Index t) {
        for (int b = 0; b < N; ++b) {
          if (!H.is_fixed(T(t, b))) strides_[N * t + b] = H.column_stride(T(t, b));
          for (int a = 0; a < N; ++a) offsets_[N * N * t + N * b + a] = H.block_offset(T(t, a), T(t, b));
        }
      })) {
    id_ = 0;
    std::rethrow_exception(failed);
  }
  id_ = H.id();
}

template <int N>
void ElementScatter<N>::add(HessianAssembler& H, Eigen::Index t, const ElementMatrix& K) const {
  double* values = H.values();
  for (int b = 0; b < N; ++b) {
    const long stride = strides_[N * t + b];
    for (int a = 0; a < N; ++a) {
      const long off = offsets_[N * N * t + N * b + a];
      if (off < 0) continue;
      double* v = values + off;
      for (int k = 0; k < 3; ++k)
        for (int r = 0; r < 3; ++r) v[k * stride + r] += K(3 * a + r, 3 * b + k);
    }
  }
}

template class ElementScatter<4>;
template class ElementScatter<10>;

}  // namespace btr
