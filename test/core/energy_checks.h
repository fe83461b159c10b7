// A finite-difference check of an energy term, shared by the energy tests.
#pragma once

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "breast_tumour_registration/fem/energy_term.h"

namespace btr::test {

// Checks a term's gradient (against central differences of the value) and Hessian
// (against central differences of the gradient, column by column) at x, with shrinking steps.
inline void check_term(const EnergyTerm& term, const TetMesh& mesh, const Points& x,
                const std::vector<std::vector<int>>& cliques = {}) {
  const int nv = static_cast<int>(x.rows());
  Eigen::VectorXd g = Eigen::VectorXd::Zero(x.size());
  term.add_gradient(x, g);
  HessianAssembler H(nv, mesh.T, {}, cliques);
  term.add_hessian(x, false, H);
  const Eigen::MatrixXd Hd = Eigen::MatrixXd(H.matrix());
  ASSERT_LT((Hd - Hd.transpose()).norm(), 1e-9 * std::max(1.0, Hd.norm())) << term.name() << ": Hessian not symmetric";

  double best_g = 1e300, best_h = 1e300;
  for (double h = 1e-4; h >= 1e-8; h *= 0.1) {
    Eigen::VectorXd gn(x.size());
    Eigen::MatrixXd Hn(x.size(), x.size());
    for (Eigen::Index i = 0; i < x.size(); ++i) {
      Points xp = x, xm = x;
      xp.data()[i] += h;
      xm.data()[i] -= h;
      gn[i] = (term.value(xp) - term.value(xm)) / (2 * h);
      Eigen::VectorXd gp = Eigen::VectorXd::Zero(x.size()), gm = Eigen::VectorXd::Zero(x.size());
      term.add_gradient(xp, gp);
      term.add_gradient(xm, gm);
      Hn.col(i) = (gp - gm) / (2 * h);
    }
    best_g = std::min(best_g, (gn - g).norm() / std::max(1e-12, g.norm()));
    best_h = std::min(best_h, (Hn - Hd).norm() / std::max(1e-12, Hd.norm()));
  }
  EXPECT_LT(best_g, 1e-6) << term.name() << " gradient";
  EXPECT_LT(best_h, 1e-6) << term.name() << " Hessian";
}

}  // namespace btr::test
