// The volume term of the stable Neo-Hookean energy on nodal averages of the volume change
// (average nodal pressure: Bonet & Burton 1998; Bonet, Marriott & Hassan 2001), so that
// linear tetrahedra do not lock as nu -> 0.5. With the element form every tetrahedron must
// keep its own volume: about 5 constraints per vertex against 3 degrees of freedom, and a
// near-incompressible mesh cannot bend. Averaged over each vertex's patch there is one per
// vertex. Together with the shear part (in this term given the materials' shear parts, as
// add_elastic_energy builds it, or as ElasticEnergy on the materials' shear_part()):
//
//   E = sum_t V_t [mu/2 (I_C - 3) - mu (J_t - 1)] + sum_n V_n lambda_n / 2 (Jbar_n - 1)^2,
//   V_n = sum_{t at n} V_t / 4,   Jbar_n = sum_{t at n} V_t J_t / (4 V_n),
//   lambda_n = sum_{t at n} V_t lambda_t / sum_{t at n} V_t   (lambda: the SNH volume stiffness),
//
// which equals the element form under any uniform deformation (patch test) and keeps its
// small-strain limit. Jbar_n is the deformed patch volume over the rest patch volume: a
// polynomial in x, defined for inverted elements like the element form.
//
// Hessian: sum_n lambda_n / V_n a_n a_n^T (a_n = dv_n/dx, PSD, couples a vertex's whole patch)
// plus sum_t s_t d2v_t/dx2 with s_t = sum_{n in t} lambda_n (Jbar_n - 1) / 4 (indefinite;
// eigen-clamped per element when projecting). The patches are its Hessian cliques.
//
// Given the shear parts, the term carries the shear part too (add_elastic_energy does so): per
// element its Hessian is then V_t (mu I + (s_t - mu) d2J/dF2), projected as one matrix in closed
// form (determinant_eigensystem.h), one 12 x 12 block per tetrahedron instead of two, and a
// projection of the sum rather than of each part (which clamps more than it needs to).
#pragma once

#include <utility>
#include <vector>

#include "breast_tumour_registration/fem/energy_term.h"
#include "breast_tumour_registration/fem/stable_neo_hookean.h"
#include "breast_tumour_registration/fem/tet_kinematics.h"

namespace btr {

class NodalVolumeEnergy : public EnergyTerm {
 public:
  /// rest    rest configuration
  /// lambda  #T volume stiffness per tetrahedron [Pa] (StableNeoHookean::lambda(), >= 0)
  /// shear   the materials' shear parts (StableNeoHookean::shear_part(): mu/2 (I_C - 3) - mu (J - 1)),
  ///         then part of this term; empty: not. InputError for a material with a volume term.
  /// material_of  #T indices into shear (empty: all 0; given without shear: InputError)
  /// element_share  #T: the part kappa_t of lambda_t kept on the element's own J_t [Pa],
  ///         0 <= kappa_t <= lambda_t (the element-share stabilisation above); empty: none.
  NodalVolumeEnergy(const TetMesh& rest, const std::vector<double>& lambda, std::vector<StableNeoHookean> shear = {},
                    std::vector<int> material_of = {}, const std::vector<double>& element_share = {});

  std::string name() const override { return shear_.empty() ? "nodal volume" : "elastic (nodal volume)"; }
  double value(const Points& x) const override;
  void add_gradient(const Points& x, Eigen::VectorXd& g) const override;
  void add_hessian(const Points& x, bool project_psd, HessianAssembler& H) const override;
  std::vector<std::vector<int>> hessian_cliques() const override { return patches_; }

  /// Jbar_n for every vertex (1 at rest; 0 for a vertex in no tetrahedron).
  Eigen::VectorXd nodal_volume_ratios(const Points& x) const;

 private:
  /// s_t = sum_{n in t} lambda_n (Jbar_n - 1) / 4 [Pa]: the tetrahedron's share of its nodes'
  /// pressures, plus kappa_t (J_t - 1) with an element share (Jt: the element's J_t).
  double element_pressure(const Eigen::VectorXd& Jbar, Eigen::Index t, double Jt) const;
  /// v_t = V_t J_t of every tetrahedron at x.
  Eigen::VectorXd element_volumes(const Points& x) const;
  Tetrahedra T_;
  std::vector<TetRestData> rest_;
  std::vector<StableNeoHookean> shear_;  // shear parts, or empty (no shear part)
  std::vector<int> material_of_;         // per tetrahedron into shear_ (with shear_)
  Eigen::VectorXd Vn_;       // rest patch volume / 4 per vertex (V_n)
  Eigen::VectorXd lambda_n_;
  Eigen::VectorXd kappa_;  // per tetrahedron: its element share kappa_t (empty: none)
  std::vector<std::vector<int>> patches_;    // per vertex: sorted vertices of its tetrahedra (empty: none)
  std::vector<std::vector<int>> tets_of_;    // per vertex: its tetrahedra
  // Scatter maps into the assembler's values, built on first use per assembler: the element
  // blocks, and for vertex n |patch|^2 block offsets (from patch_offset_[n]; -1: a fixed vertex);
  // patch_stride_[n]: where vertex n's |patch| entries start in per-patch-vertex arrays.
  void build_scatter(const HessianAssembler& H) const;
  mutable TetScatter tet_scatter_;  // its assembler id also marks the patch maps as current
  mutable std::vector<long> patch_offsets_;
  mutable std::vector<size_t> patch_offset_, patch_stride_;
  // The patch terms are added column by column, in parallel: vertex j's blocks (i, j) live in
  // its own three columns, so no two threads write one entry. Per vertex j (from column_start_[j]):
  // the vertices n whose patch holds j, ascending (so each entry sums its terms in the order of a
  // serial loop over n, whatever the threads), and j's position in that patch.
  std::vector<size_t> column_start_;
  std::vector<std::pair<int, int>> column_patches_;
  // Per-call work arrays kept between calls (per tetrahedron: its gradient, dv_t/dx and its 12 x 12 block;
  // per patch vertex: a_n), as ElasticEnergy keeps its blocks: 10 MB allocated and freed per
  // Hessian on an 8k-tet mesh otherwise.
  mutable std::vector<Vec12> grad_, dv_;
  mutable std::vector<Mat12> ke_;
  mutable std::vector<Vec3> a_;
};

}  // namespace btr
