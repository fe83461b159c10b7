// Anderson acceleration of a fixed-point iteration x <- G(x) (type II, Walker and Ni 2011;
// used for ICP by Pavlov et al. 2018 and Zhang et al. 2022): from the last m+1 pairs
// (x_j, G(x_j)) the next iterate is the combination of the G(x_j) whose residuals
// f_j = G(x_j) - x_j combine to the smallest norm:
//
//   gamma = argmin |f_k - dF gamma|,   x_{k+1} = G(x_k) - dG gamma,
//
// with dF, dG the differences of successive residuals and map values. On a linear contraction
// it is GMRES on the residual equation; on the surface step's projection/Newton alternation it
// cuts the slow tangential relaxation of soft tissue. It has no safeguard of its own: the
// caller accepts a proposal only where its merit function decreases and resets otherwise.
#pragma once

#include <deque>

#include <Eigen/Core>

namespace btr {

class AndersonAcceleration {
 public:
  /// depth m >= 1: the number of difference columns kept.
  explicit AndersonAcceleration(int depth);

  /// x: the iterate the map was applied to; g = G(x). Returns the proposed next iterate (g
  /// itself until two pairs are known, or where the least-squares problem is degenerate).
  Eigen::VectorXd next(const Eigen::VectorXd& x, const Eigen::VectorXd& g);
  /// Forget the history (after a rejected proposal, or when the map changes).
  void reset();
  /// The difference columns the last proposal used (0: it was the plain iterate).
  int columns() const { return static_cast<int>(dF_.size()); }

 private:
  int depth_;
  std::deque<Eigen::VectorXd> dF_, dG_;
  Eigen::VectorXd f_last_, g_last_;
};

}  // namespace btr
