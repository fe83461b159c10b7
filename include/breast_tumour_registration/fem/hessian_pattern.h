// Sparse Hessian over the free degrees of freedom, with a pattern fixed once from the
// mesh connectivity (3x3 blocks for every pair of vertices sharing a tetrahedron, or a
// user clique such as a constraint anchored in a triangle). Fixed vertices (the chest
// wall) are eliminated: their rows and columns are not stored, which keeps the
// system symmetric positive definite. The matrix is stored in full (both triangles)
// so that it can be multiplied and factorized without conversion.
#pragma once

#include <vector>

#include <Eigen/SparseCore>

#include "breast_tumour_registration/base/types.h"

namespace btr {

class HessianAssembler {
 public:
  /// num_vertices   #V
  /// T              #T by 4 tetrahedra (couple their 4 vertices)
  /// fixed          #V flags; fixed vertices have no DOFs in the matrix (may be empty)
  /// extra_cliques  further vertex groups that must be coupled (e.g. constraint anchors)
  HessianAssembler(int num_vertices, const Tetrahedra& T, const std::vector<bool>& fixed,
                   const std::vector<std::vector<int>>& extra_cliques = {});

  int num_vertices() const { return static_cast<int>(free_index_.size()); }
  int num_free_vertices() const { return num_free_; }
  int num_free_dofs() const { return 3 * num_free_; }
  /// Free index of vertex v, or -1 when v is fixed.
  int free_index(int v) const { return free_index_[v]; }
  bool is_fixed(int v) const { return free_index_[v] < 0; }

  void set_zero();
  /// Adds B to the block (vi, vj). Blocks touching a fixed vertex are dropped.
  /// Throws std::logic_error if the pair is not in the pattern.
  void add_block(int vi, int vj, const Mat3& B);
  /// Position of entry (3 fi, 3 fj) of the free-vertex block in valuePtr(), for
  /// callers that precompute element scatter maps; -1 if either vertex is fixed.
  long block_offset(int vi, int vj) const;
  /// Stride between the block's columns k and k+1 (rows of column 3 fj).
  long column_stride(int vj) const { return 3 * static_cast<long>(nbrs_[free_index_[vj]].size()); }
  double* values() { return H_.valuePtr(); }
  /// Unique per assembler instance (lets element terms cache scatter maps safely).
  unsigned long id() const { return id_; }

  const Eigen::SparseMatrix<double>& matrix() const { return H_; }

  /// Full 3#V vector -> free 3#F vector, and back (fixed entries left untouched).
  Eigen::VectorXd gather(const Eigen::VectorXd& full) const;
  void scatter_add(const Eigen::VectorXd& reduced, double scale, Eigen::VectorXd& full) const;

 private:
  std::vector<int> free_index_;          // vertex -> free vertex index or -1
  std::vector<int> free_vertex_;         // free vertex index -> vertex
  std::vector<std::vector<int>> nbrs_;   // free vertex -> sorted free neighbour indices (incl. self)
  int num_free_ = 0;
  unsigned long id_;
  Eigen::SparseMatrix<double> H_;
};

/// Where every element's N x N vertex blocks sit in one assembler's values, so that element
/// terms scatter their 3N x 3N matrices without a pattern look-up per block. Built once per
/// assembler (HessianAssembler::id()); ElasticEnergy and NodalVolumeEnergy keep one for their
/// tetrahedra (N = 4), QuadraticElasticEnergy one for its 10-node elements.
template <int N>
class ElementScatter {
 public:
  using Elements = Eigen::Matrix<int, Eigen::Dynamic, N, Eigen::RowMajor>;
  using ElementMatrix = Eigen::Matrix<double, 3 * N, 3 * N>;
  bool built_for(const HessianAssembler& H) const { return id_ == H.id(); }
  /// Throws std::logic_error (block_offset) for a pair outside the pattern.
  void build(const HessianAssembler& H, const Elements& T);
  /// Adds K (vertex blocks in T.row(t) order) to H; blocks of fixed vertices are dropped.
  void add(HessianAssembler& H, Eigen::Index t, const ElementMatrix& K) const;

 private:
  unsigned long id_ = 0;
  std::vector<long> offsets_;  // N * N per element, -1 where a vertex is fixed
  std::vector<long> strides_;  // N per element
};
using TetScatter = ElementScatter<4>;
extern template class ElementScatter<4>;
extern template class ElementScatter<10>;

}  // namespace btr
