// Linear-skinning subspace (thesis Sec. 3.4 and 4.3, eq. 3.10 and 3.11; Brandt et al. 2018):
// k handles chosen by farthest point sampling (Euclidean, seeded with the landmark vertices
// so that the result is deterministic), each with a compactly supported radial weight,
// and one affine transform (12 DOFs) per handle:
//
//   x_i = x0_i + sum_j w_ij A_j [X_i; 1],   A_j in R^{3x4}
//
// Support radius (thesis eq. 4.1, Nasikun & Hildebrandt 2022, adapted to volume): each
// handle's ball holds sigma * volume / k, i.e. r = (3 sigma V / (4 pi k))^(1/3). The thesis
// writes sqrt(sigma V / (k pi)), which is not a length for a volume V; the cube root is the
// dimensionally consistent form of the same heuristic. r is never below 1.5 times the
// sampling's covering radius, so every vertex is reached by at least one handle.
#pragma once

#include <vector>

#include <Eigen/SparseCore>

#include "breast_tumour_registration/base/types.h"

namespace btr {

struct SubspaceOptions {
  int handles = 60;     ///< k, including the seed vertices
  double sigma = 6.0;   ///< mean number of handle supports covering a point
};

struct SkinningSubspace {
  std::vector<int> handles;  ///< handle vertices (seeds first)
  double radius = 0;         ///< support radius [m]
  /// 3#V by 12k basis: d vec(x) / dq. Rows of fixed vertices are zero.
  Eigen::SparseMatrix<double> basis;
};

/// Farthest point sampling of `count` vertices of V among `candidates` (all when empty),
/// starting from `seeds`. Deterministic. Returns seeds followed by the new samples and the
/// covering radius (largest distance from a candidate to its nearest sample).
std::vector<int> farthest_point_sampling(const Points& V, const std::vector<int>& seeds, int count,
                                         const std::vector<int>& candidates, double* covering_radius = nullptr);

/// Builds the subspace for rest positions X (#V by 3) of a body of volume `volume` [m^3].
/// Vertices flagged in `fixed` get zero rows (the chest wall does not move).
/// Throws InputError for fewer than one handle or a non-positive sigma.
SkinningSubspace build_skinning_subspace(const Points& X, double volume, const std::vector<int>& seeds,
                                         const std::vector<bool>& fixed, const SubspaceOptions& opt);

}  // namespace btr
