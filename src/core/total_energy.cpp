#include "breast_tumour_registration/core/total_energy.h"

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

}  // namespace btr
