#include "breast_tumour_registration/fem/subspace_solver.h"

#include <Eigen/Cholesky>
#include <algorithm>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/fem/pcg.h"

namespace btr {
namespace {

// The subspace solve: x = x0 + U q, the reduced Hessian U^T H U dense (12k by 12k for k
// skinning handles), factorized with LDLT after a tiny diagonal shift against the basis'
// redundancy. Later iterations try PCG on U^T H U, applied as three sparse products, with the
// lagged dense factor as preconditioner; the product is formed only when PCG falls short.
class SubspaceSolve : public NewtonLinearSolve {
 public:
  SubspaceSolve(const Eigen::SparseMatrix<double>& U) : U_(U), Ut_(U.transpose()) {}
  Eigen::VectorXd reduce(const Eigen::VectorXd& g_free) const override { return Ut_ * g_free; }
  Eigen::VectorXd expand(const Eigen::VectorXd& d) const override { return U_ * d; }
  void set_hessian(const HessianAssembler& H, const LowRankHessian& low) override {
    H_ = &H.matrix();
    M_ = &low.M;
    UtW_ = Ut_ * low.W;
  }
  bool has_factor() const override { return have_factor_; }
  bool lagged_solve(const Eigen::VectorXd& rhs, double eta, int max_iterations, Eigen::VectorXd& d, int& its) override {
    const auto Hs = H_->selfadjointView<Eigen::Lower>();
    auto apply = [&](const Eigen::VectorXd& v) {
      Eigen::VectorXd out = Ut_ * (Hs * (U_ * v));
      if (UtW_.cols()) out.noalias() -= UtW_ * (*M_ * (UtW_.transpose() * v));
      return out;
    };
    return preconditioned_cg(apply, [&](const Eigen::VectorXd& v) { return Eigen::VectorXd(ldlt_.solve(v)); }, rhs, eta,
                             max_iterations, d, its);
  }
  bool factorize(bool, int&) override {
    // U^T H U by column blocks on both cores (Eigen's sparse product is sequential).
    const Eigen::Index m = U_.cols(), half = m / 2;
    Eigen::MatrixXd Hr(m, m);
#pragma omp parallel for schedule(static, 1)
    for (int part = 0; part < 2; ++part) {
      const Eigen::Index c0 = part == 0 ? 0 : half, nc = part == 0 ? half : m - half;
      const Eigen::SparseMatrix<double> Ub = U_.middleCols(c0, nc);
      Hr.middleCols(c0, nc) = Eigen::MatrixXd(Ut_ * (*H_ * Ub));
    }
    if (UtW_.cols()) Hr.noalias() -= UtW_ * *M_ * UtW_.transpose();
    const double shift = 1e-12 * std::max(Hr.diagonal().cwiseAbs().maxCoeff(), 1e-300);
    Hr.diagonal().array() += shift;
    ldlt_.compute(Hr);
    have_factor_ = true;
    return true;
  }
  Eigen::VectorXd solve(const Eigen::VectorXd& rhs) override { return ldlt_.solve(rhs); }
  // The reduced problem is small and projected: the exact Hessian's tail is not worth its risk here.
  bool supports_exact_hessian() const override { return false; }
  void forget_factor() override { have_factor_ = false; }

 private:
  const Eigen::SparseMatrix<double>& U_;
  const Eigen::SparseMatrix<double> Ut_;
  const Eigen::SparseMatrix<double>* H_ = nullptr;
  const Eigen::MatrixXd* M_ = nullptr;
  Eigen::MatrixXd UtW_;
  Eigen::LDLT<Eigen::MatrixXd> ldlt_;
  bool have_factor_ = false;
};

}  // namespace

NewtonResult solve_subspace_newton(const TotalEnergy& energy, HessianAssembler& H,
                                   const Eigen::SparseMatrix<double>& basis, const Tetrahedra& tets, Points& x,
                                   const NewtonOptions& opt) {
  if (basis.rows() != x.size()) throw InputError("subspace basis has the wrong number of rows");
  // Restrict the basis to the free DOFs (the assembler's ordering).
  std::vector<Eigen::Triplet<double>> trip;
  for (int k = 0; k < basis.outerSize(); ++k)
    for (Eigen::SparseMatrix<double>::InnerIterator it(basis, k); it; ++it) {
      const int v = static_cast<int>(it.row() / 3);
      if (H.is_fixed(v)) continue;
      trip.emplace_back(3 * H.free_index(v) + it.row() % 3, it.col(), it.value());
    }
  Eigen::SparseMatrix<double> U(H.num_free_dofs(), basis.cols());
  U.setFromTriplets(trip.begin(), trip.end());
  SubspaceSolve linear(U);
  return newton_minimize(energy, H, tets, linear, x, opt);
}

}  // namespace btr
