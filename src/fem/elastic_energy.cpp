#include "breast_tumour_registration/fem/elastic_energy.h"

#include <algorithm>
#include <cmath>
#include <string>
#include <utility>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/fem/material_assignment.h"
#include "breast_tumour_registration/fem/nodal_volume_energy.h"

namespace btr {

ElasticEnergy::ElasticEnergy(const TetMesh& rest, std::vector<StableNeoHookean> materials,
                             std::vector<int> material_of)
    : T_(rest.T), rest_(compute_rest_data(rest)), materials_(std::move(materials)),
      material_of_(checked_material_of(std::move(material_of), materials_.size(), T_.rows(), "ElasticEnergy")) {}

double ElasticEnergy::element_value(const Points& x, Eigen::Index t) const {
  const Mat3 F = deformation_gradient(x, T_.row(t), rest_[t].Dm_inv);
  return rest_[t].volume * materials_[material_of_[t]].psi(F);
}

Vec12 ElasticEnergy::element_gradient(const Points& x, Eigen::Index t) const {
  const Mat3 F = deformation_gradient(x, T_.row(t), rest_[t].Dm_inv);
  return tet_gradient_from_stress(materials_[material_of_[t]].pk1(F), rest_[t].Dm_inv, rest_[t].volume);
}

Mat12 ElasticEnergy::element_hessian(const Points& x, Eigen::Index t, bool project_psd) const {
  const Mat3 F = deformation_gradient(x, T_.row(t), rest_[t].Dm_inv);
  const auto& mat = materials_[material_of_[t]];
  return tet_hessian_from_stress_hessian(project_psd ? mat.clamped_hessian(F) : mat.hessian(F), rest_[t].Dm_inv,
                                         rest_[t].volume);
}

double ElasticEnergy::value(const Points& x) const {
  double e = 0;
#pragma omp parallel for reduction(+ : e) schedule(static)
  for (Eigen::Index t = 0; t < T_.rows(); ++t) e += element_value(x, t);
  return e;
}

void ElasticEnergy::add_gradient(const Points& x, Eigen::VectorXd& g) const {
  std::vector<Vec12> ge(T_.rows());
#pragma omp parallel for schedule(static)
  for (Eigen::Index t = 0; t < T_.rows(); ++t) ge[t] = element_gradient(x, t);
  for (Eigen::Index t = 0; t < T_.rows(); ++t)
    for (int a = 0; a < 4; ++a) g.segment<3>(3 * T_(t, a)) += ge[t].segment<3>(3 * a);
}

void ElasticEnergy::add_hessian(const Points& x, bool project_psd, HessianAssembler& H) const {
  const Eigen::Index nt = T_.rows();
  if (!scatter_.built_for(H)) scatter_.build(H, T_);
  buffer_.resize(nt);
#pragma omp parallel for schedule(static)
  for (Eigen::Index t = 0; t < nt; ++t) buffer_[t] = element_hessian(x, t, project_psd);
  for (Eigen::Index t = 0; t < nt; ++t) scatter_.add(H, t, buffer_[t]);
}

void add_elastic_energy(TotalEnergy& energy, const TetMesh& rest, const std::vector<StableNeoHookean>& materials,
                        const std::vector<int>& material_of, VolumeForm form, double nodal_element_share) {
  if (form == VolumeForm::Auto) throw InputError("add_elastic_energy: resolve the volume form first");
  if (!(nodal_element_share >= 0) || !std::isfinite(nodal_element_share))
    throw InputError("material.nodal_element_share must be a finite number >= 0 (in units of the shear modulus), not " +
                     std::to_string(nodal_element_share));
  if (form == VolumeForm::Element) {
    energy.add(std::make_shared<ElasticEnergy>(rest, materials, material_of));
    return;
  }
  // One term for the shear part and the volume term on nodal averages (nodal_volume_energy.h):
  // one projected block per tetrahedron.
  std::vector<int> of = checked_material_of(material_of, materials.size(), rest.T.rows(), "add_elastic_energy");
  std::vector<StableNeoHookean> shear;
  for (const auto& m : materials) shear.push_back(m.shear_part());
  std::vector<double> lambda(rest.T.rows());
  for (Eigen::Index t = 0; t < rest.T.rows(); ++t) lambda[t] = materials[of[t]].lambda();
  std::vector<double> kappa;
  if (nodal_element_share > 0)
    for (Eigen::Index t = 0; t < rest.T.rows(); ++t) kappa.push_back(std::min(nodal_element_share * materials[of[t]].mu(), lambda[t]));
  energy.add(std::make_shared<NodalVolumeEnergy>(rest, lambda, std::move(shear), std::move(of), kappa));
}

}  // namespace btr
