// One term of the quasi-static energy E(x) (thesis Sec. 3.2). Each term gives its value,
// adds its gradient to a full 3#V vector, and adds its Hessian (optionally projected to
// be positive semi-definite) into the shared sparse assembler.
#pragma once

#include <string>
#include <vector>

#include "breast_tumour_registration/base/types.h"
#include "breast_tumour_registration/fem/hessian_pattern.h"

namespace btr {

/// A dense low-rank part subtracted from a term's sparse Hessian: d2E/dx2 = H_sparse - W M W^T.
/// It arises where a few unknowns coupled to many vertices are eliminated (a rigid pose
/// solved inside surface springs): the solvers apply it by the Woodbury identity instead of
/// filling the sparse pattern. W  3#V by k (full DOF layout), M  k by k symmetric PSD.
struct LowRankHessian {
  Eigen::MatrixXd W;
  Eigen::MatrixXd M;
};

class EnergyTerm {
 public:
  virtual ~EnergyTerm() = default;
  virtual std::string name() const = 0;
  /// x  #V by 3 current positions [m]; returns joules.
  virtual double value(const Points& x) const = 0;
  /// Adds dE/dx to g (3#V, layout [x0 y0 z0 x1 ...]).
  virtual void add_gradient(const Points& x, Eigen::VectorXd& g) const = 0;
  /// Adds d2E/dx2 into H; with project_psd, each local block is made PSD first.
  virtual void add_hessian(const Points& x, bool project_psd, HessianAssembler& H) const = 0;
  /// Vertex groups whose blocks add_hessian fills beyond those of shared tetrahedra (the
  /// assembler's pattern must include them); most terms need none.
  virtual std::vector<std::vector<int>> hessian_cliques() const { return {}; }
  /// Appends the low-rank part subtracted from add_hessian's matrix; most terms have none.
  virtual void add_low_rank_hessian(const Points& /*x*/, std::vector<LowRankHessian>& /*parts*/) const {}
};

}  // namespace btr
