// Surface springs (thesis eqs. 4.2 and 4.3: a soft point spring and a stiff point-to-plane
// spring per skin vertex) whose supine scan may move rigidly: the pose is solved jointly
// with the deformation where no rigid region pins it (issue 10). With P the rigid map from
// the model frame into the scan's frame and (y_j, n_j) the projection of skin vertex j:
//
//   c(x) = min_P  sum_j 1/2 r_j^T A_j r_j,   r_j = P x_j - y_j,   A_j = w_p I + w_n n_j n_j^T
//
// (and optional point springs, A_j = w I, on anchors such as landmarks, sharing the pose).
//
// As in RigidFreeLandmarkEnergy the pose is eliminated (variable projection): P*(x) by
// Gauss-Newton on 6 unknowns, the gradient Q^T A_j r_j at P* (Q = rotation of P*, envelope
// theorem), and the Hessian as the sparse per-vertex blocks Q^T A_j Q minus a rank-6 part
// W M W^T (W_j = Q^T A_j J_j, M = (sum J^T A J)^-1, J_j the derivative of P x_j with respect
// to a twist), applied by the solvers through the Woodbury identity. The Hessian is the
// Gauss-Newton one: exact where the residuals vanish, PSD everywhere.
#pragma once

#include <vector>

#include "breast_tumour_registration/fem/energy_term.h"
#include "breast_tumour_registration/geometry/anchor.h"
#include "breast_tumour_registration/geometry/rigid_transform.h"

namespace btr {

class RigidFreeSurfaceEnergy : public EnergyTerm {
 public:
  /// point_weight, plane_weight [N/m] per constrained vertex (finite, >= 0, not both 0).
  RigidFreeSurfaceEnergy(double point_weight, double plane_weight);

  /// Replaces the surface correspondences: vertex j of the mesh is held to point y (unit
  /// normal n), both in the scan's frame. Throws InputError for non-finite input or a zero normal.
  void set(const std::vector<int>& vertices, const Points& y, const Points& n);
  /// Point springs that share the pose and stay across set() calls (landmarks: on a nearly
  /// rotationally symmetric breast the surface alone leaves the rotation about its axis to
  /// the model's errors). weight [N/m]; targets in the scan's frame, one row per anchor.
  void set_points(const std::vector<Anchor>& anchors, const Points& targets, double weight);
  std::size_t size() const { return anchors_.size(); }

  std::string name() const override { return "surface (pose free)"; }
  double value(const Points& x) const override;
  void add_gradient(const Points& x, Eigen::VectorXd& g) const override;
  void add_hessian(const Points& x, bool project_psd, HessianAssembler& H) const override;
  void add_low_rank_hessian(const Points& x, std::vector<LowRankHessian>& parts) const override;

  /// The best pose for x: model frame -> scan frame. Needs >= 3 correspondences.
  Rigid pose(const Points& x) const;
  /// The point the pose turns about at x under pose P: the mean of the correspondences' P x
  /// (surface and point anchors alike). The twist xi = (omega, tau) moves each by
  /// twist_jacobian(P x_j, centre) xi.
  Vec3 turning_centre(const Points& x, const Rigid& P) const;
  /// d(P x_j) / d xi for the small motion exp(xi) about `centre`: [-(q - centre)^, I].
  static Eigen::Matrix<double, 3, 6> twist_jacobian(const Vec3& q, const Vec3& centre);

 private:
  void rebuild();
  double point_weight_, plane_weight_;
  // Surface and point correspondences alike: anchor, target, metric A_j.
  std::vector<Anchor> surface_anchors_, point_anchors_, anchors_;
  std::vector<Vec3> surface_y_, point_y_, y_;
  std::vector<Mat3> surface_A_, point_A_, A_;
  mutable Rigid warm_ = Rigid::Identity();  // last pose found: the next Gauss-Newton start
};

}  // namespace btr
