#include "breast_tumour_registration/fem/hessian_factor.h"

#include "breast_tumour_registration/base/errors.h"

namespace btr {

bool factorize_exact_or_projected(const TotalEnergy& energy, const Points& x, HessianAssembler& H, HessianLlt& llt,
                                  const std::string& what) {
  llt.cholmod().print = 0;
  for (const bool project : {false, true}) {
    energy.hessian(x, project, H);
    llt.compute(H.matrix());
    if (llt.info() == Eigen::Success) return project;
  }
  throw SolverError(what + " cannot be factorized");
}

}  // namespace btr
