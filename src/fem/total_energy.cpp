#include "breast_tumour_registration/fem/total_energy.h"

namespace btr {

double TotalEnergy::value(const Points& x) const {
  double e = 0;
  for (const auto& t : terms_) e += t->value(x);
  return e;
}

Eigen::VectorXd TotalEnergy::gradient(const Points& x) const {
  Eigen::VectorXd g = Eigen::VectorXd::Zero(x.size());
  for (const auto& t : terms_) t->add_gradient(x, g);
  return g;
}

void TotalEnergy::hessian(const Points& x, bool project_psd, HessianAssembler& H) const {
  H.set_zero();
  for (const auto& t : terms_) t->add_hessian(x, project_psd, H);
}

LowRankHessian TotalEnergy::low_rank_hessian(const Points& x, const HessianAssembler& H) const {
  std::vector<LowRankHessian> parts;
  for (const auto& t : terms_) t->add_low_rank_hessian(x, parts);
  Eigen::Index k = 0;
  for (const auto& p : parts) k += p.M.rows();
  LowRankHessian out;
  out.W.setZero(H.num_free_dofs(), k);
  out.M.setZero(k, k);
  Eigen::Index c = 0;
  for (const auto& p : parts) {
    for (Eigen::Index j = 0; j < p.W.cols(); ++j) out.W.col(c + j) = H.gather(p.W.col(j));
    out.M.block(c, c, p.M.rows(), p.M.cols()) = p.M;
    c += p.M.rows();
  }
  return out;
}

std::vector<std::vector<int>> TotalEnergy::hessian_cliques(std::vector<std::vector<int>> extra) const {
  std::vector<std::vector<int>> all;
  for (const auto& t : terms_) {
    auto c = t->hessian_cliques();
    all.insert(all.end(), std::make_move_iterator(c.begin()), std::make_move_iterator(c.end()));
  }
  all.insert(all.end(), std::make_move_iterator(extra.begin()), std::make_move_iterator(extra.end()));
  return all;
}

}  // namespace btr
