#include "breast_tumour_registration/fem/gravity_energy.h"

#include <utility>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/fem/tet_kinematics.h"

namespace btr {

GravityEnergy::GravityEnergy(const TetMesh& rest, double density, const Vec3& gravity)
    : masses_(lumped_masses(rest, density)), gravity_(gravity) {
  if (!gravity.allFinite()) throw InputError("gravity vector must be finite");
}

GravityEnergy::GravityEnergy(Eigen::VectorXd masses, const Vec3& gravity) : masses_(std::move(masses)), gravity_(gravity) {
  if (!gravity.allFinite() || !masses_.allFinite()) throw InputError("gravity vector and masses must be finite");
}

double GravityEnergy::value(const Points& x) const { return -(masses_.transpose() * (x * gravity_))(0); }

void GravityEnergy::add_gradient(const Points&, Eigen::VectorXd& g) const {
  for (Eigen::Index i = 0; i < masses_.size(); ++i) g.segment<3>(3 * i) -= masses_[i] * gravity_;
}

}  // namespace btr
