// The sum of energy terms minimized by the Newton solver.
#pragma once

#include <memory>
#include <vector>

#include "breast_tumour_registration/fem/energy_term.h"

namespace btr {

class TotalEnergy {
 public:
  void add(std::shared_ptr<const EnergyTerm> term) { terms_.push_back(std::move(term)); }
  const std::vector<std::shared_ptr<const EnergyTerm>>& terms() const { return terms_; }

  double value(const Points& x) const;
  /// Every term's hessian_cliques() followed by `extra`: what the assembler's pattern needs.
  std::vector<std::vector<int>> hessian_cliques(std::vector<std::vector<int>> extra = {}) const;
  /// Full 3#V gradient.
  Eigen::VectorXd gradient(const Points& x) const;
  /// Zeroes H and assembles every term into it.
  void hessian(const Points& x, bool project_psd, HessianAssembler& H) const;
  /// The terms' low-rank parts gathered to the assembler's free DOFs as one W (free DOFs by
  /// k) and a block-diagonal M; W has no columns when no term has one.
  LowRankHessian low_rank_hessian(const Points& x, const HessianAssembler& H) const;

 private:
  std::vector<std::shared_ptr<const EnergyTerm>> terms_;
};

}  // namespace btr
