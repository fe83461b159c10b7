// Zero-rest-length springs from anchored points to targets, each with its own 3x3 stiffness
// (metric) K_i:  E(x) = 1/2 sum_i (p_i(x) - t_i)^T K_i (p_i(x) - t_i),
// where p_i(x) is an Anchor (a vertex or a barycentric point). The thesis's constraints are
// the two metrics of this one term:
//   point-to-point (eq. 4.2, landmarks and projections):  K = w I;
//   point-to-plane (eq. 4.3, the point slides in the plane through t with unit normal n):  K = w n n^T;
// and a skin vertex held by both is one spring with K = w_point I + w_plane n n^T.
#pragma once

#include <string>
#include <vector>

#include "breast_tumour_registration/fem/energy_term.h"
#include "breast_tumour_registration/geometry/anchor.h"

namespace btr {

class SpringEnergy : public EnergyTerm {
 public:
  explicit SpringEnergy(std::string name = "springs") : name_(std::move(name)) {}

  /// K [N/m] symmetric positive semi-definite and finite, target finite; throws InputError otherwise.
  void add(const Anchor& anchor, const Vec3& target, const Mat3& stiffness);
  /// K = weight I; weight [N/m] finite and >= 0.
  void add_point(const Anchor& anchor, const Vec3& target, double weight);
  /// K = weight n n^T with n = normal / |normal|; throws InputError for a zero or non-finite normal.
  void add_plane(const Anchor& anchor, const Vec3& point, const Vec3& normal, double weight);
  /// K = point_weight I + plane_weight n n^T: a point held to `point` and, more stiffly, to its tangent plane.
  void add_point_and_plane(const Anchor& anchor, const Vec3& point, const Vec3& normal, double point_weight,
                           double plane_weight);
  void clear();
  std::size_t size() const { return anchors_.size(); }

  std::string name() const override { return name_; }
  double value(const Points& x) const override;
  void add_gradient(const Points& x, Eigen::VectorXd& g) const override;
  /// Constant and PSD: project_psd changes nothing.
  void add_hessian(const Points& x, bool project_psd, HessianAssembler& H) const override;

  const std::vector<Anchor>& anchors() const { return anchors_; }
  const std::vector<Vec3>& targets() const { return targets_; }

 private:
  void push(const Anchor& anchor, const Vec3& target, const Mat3& stiffness);  ///< target checked, K trusted
  std::string name_;
  std::vector<Anchor> anchors_;
  std::vector<Vec3> targets_;
  std::vector<Mat3> stiffness_;
};

}  // namespace btr
