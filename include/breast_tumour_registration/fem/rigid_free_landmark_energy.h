// Landmark springs whose supine targets may move rigidly: the pose of the supine data in
// the model frame is an unknown solved jointly with the deformation (issue 10). For a
// fixed deformation x the best pose is the Kabsch fit T*(x) of the supine points onto the
// deformed anchors, and the term is the springs' energy at that pose:
//
//   c(x) = min_T  w/2 sum_i |a_i(x) - T p_i|^2           (thesis eq. 4.2 with T unknown)
//
// Eliminating T this way (variable projection) keeps the unknowns those of the mesh, so
// the Newton solvers are unchanged: the gradient is the springs' gradient at T*(x)
// (envelope theorem), and the Hessian is the Schur complement of the pose block,
//   d2c/dx2 = w A^T A - (w A^T J) f_TT^-1 (w J^T A),
// J (3n by 6) the derivative of T p_i with respect to a twist of T about the targets'
// centroid, f_TT = w J^T J - w sum_i r_i . d2(T p_i)/dtwist2. With project_psd the
// curvature part of f_TT is dropped (Gauss-Newton), which makes the block a projector
// w A^T (I - J (J^T J)^-1 J^T) A: PSD. Gravity and the fixed chest wall then decide the
// absolute position that the landmarks alone leave open, so the breast's own sag is no
// longer absorbed into the pose as a Kabsch fit on the prone landmarks does.
#pragma once

#include <vector>

#include "breast_tumour_registration/fem/energy_term.h"
#include "breast_tumour_registration/geometry/anchor.h"
#include "breast_tumour_registration/geometry/rigid_transform.h"

namespace btr {

class RigidFreeLandmarkEnergy : public EnergyTerm {
 public:
  /// weight [N/m]; anchors on the model; data: the supine landmark points (any frame),
  /// one per anchor. Needs >= 3 landmarks that are not collinear (InputError otherwise).
  RigidFreeLandmarkEnergy(double weight, std::vector<Anchor> anchors, Points data);

  std::string name() const override { return "landmarks (pose free)"; }
  double value(const Points& x) const override;
  void add_gradient(const Points& x, Eigen::VectorXd& g) const override;
  void add_hessian(const Points& x, bool project_psd, HessianAssembler& H) const override;

  /// The best pose for x: data frame -> model frame (Kabsch of the data onto the anchors).
  Rigid pose(const Points& x) const;
  /// Every anchor vertex: the Hessian couples all of them (one assembler clique).
  std::vector<int> clique() const;

 private:
  Points anchor_positions(const Points& x) const;
  double weight_;
  std::vector<Anchor> anchors_;
  Points data_;
};

}  // namespace btr
