#include "breast_tumour_registration/fem/anderson_acceleration.h"

#include <Eigen/QR>

#include "breast_tumour_registration/base/errors.h"

namespace btr {

AndersonAcceleration::AndersonAcceleration(int depth) : depth_(depth) {
  if (depth < 1) throw InputError("Anderson acceleration: depth must be >= 1");
}

void AndersonAcceleration::reset() {
  dF_.clear();
  dG_.clear();
  f_last_.resize(0);
  g_last_.resize(0);
}

Eigen::VectorXd AndersonAcceleration::next(const Eigen::VectorXd& x, const Eigen::VectorXd& g) {
  if (x.size() != g.size()) throw InputError("Anderson acceleration: x and G(x) differ in size");
  if (f_last_.size() && f_last_.size() != x.size()) reset();  // another problem: start over
  const Eigen::VectorXd f = g - x;
  if (f_last_.size()) {
    dF_.push_back(f - f_last_);
    dG_.push_back(g - g_last_);
    if (static_cast<int>(dF_.size()) > depth_) {
      dF_.pop_front();
      dG_.pop_front();
    }
  }
  f_last_ = f;
  g_last_ = g;
  if (dF_.empty()) return g;
  const Eigen::Index m = static_cast<Eigen::Index>(dF_.size());
  Eigen::MatrixXd F(x.size(), m), G(x.size(), m);
  for (Eigen::Index j = 0; j < m; ++j) {
    F.col(j) = dF_[static_cast<size_t>(j)];
    G.col(j) = dG_[static_cast<size_t>(j)];
  }
  Eigen::ColPivHouseholderQR<Eigen::MatrixXd> qr(F);
  qr.setThreshold(1e-10);  // drop columns that repeat the others (a stalled direction)
  if (qr.rank() == 0) return g;
  const Eigen::VectorXd gamma = qr.solve(f);
  if (!gamma.allFinite()) return g;
  return g - G * gamma;
}

}  // namespace btr
