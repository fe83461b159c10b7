// Volume-weighted elastic energy E = sum_t vol_t psi(F_t) (thesis eq. 3.6), with one
// stable Neo-Hookean material per tetrahedron (so a stiffer tumour can be modelled).
#pragma once

#include <memory>
#include <string>
#include <vector>

#include "breast_tumour_registration/fem/energy_term.h"
#include "breast_tumour_registration/fem/stable_neo_hookean.h"
#include "breast_tumour_registration/fem/tet_kinematics.h"
#include "breast_tumour_registration/fem/total_energy.h"
#include "breast_tumour_registration/fem/volume_form.h"

namespace btr {

class ElasticEnergy : public EnergyTerm {
 public:
  /// rest        rest configuration (defines Dm^-1 and volumes)
  /// materials   list of materials; material_of[t] indexes it (empty: all use materials[0])
  ElasticEnergy(const TetMesh& rest, std::vector<StableNeoHookean> materials, std::vector<int> material_of = {});

  std::string name() const override { return "elastic"; }
  double value(const Points& x) const override;
  void add_gradient(const Points& x, Eigen::VectorXd& g) const override;
  void add_hessian(const Points& x, bool project_psd, HessianAssembler& H) const override;

  /// Element kernels (per tetrahedron): energy, 12-vector gradient, 12x12 Hessian.
  double element_value(const Points& x, Eigen::Index t) const;
  Vec12 element_gradient(const Points& x, Eigen::Index t) const;
  Mat12 element_hessian(const Points& x, Eigen::Index t, bool project_psd) const;

  const Tetrahedra& tets() const { return T_; }
  const std::vector<TetRestData>& rest_data() const { return rest_; }

 private:
  Tetrahedra T_;
  std::vector<TetRestData> rest_;
  std::vector<StableNeoHookean> materials_;
  std::vector<int> material_of_;
  mutable TetScatter scatter_;  // built on first use per assembler
  mutable std::vector<Mat12> buffer_;
};

/// Adds the stable Neo-Hookean energy of the materials to `energy`: one ElasticEnergy (Element
/// form), or one NodalVolumeEnergy with their shear parts (Nodal form), each tetrahedron keeping
/// min(nodal_element_share mu, lambda) of its volume stiffness on its own J
/// (MaterialParameters::nodal_element_share; InputError below 0). `form` must be resolved (not
/// Auto). material_of as for ElasticEnergy.
void add_elastic_energy(TotalEnergy& energy, const TetMesh& rest, const std::vector<StableNeoHookean>& materials,
                        const std::vector<int>& material_of, VolumeForm form, double nodal_element_share);

}  // namespace btr
