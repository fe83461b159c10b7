// Rigid transforms and the closed-form landmark alignment (Kabsch 1976 / Umeyama 1991
// without scaling): the initial guess of the rigid alignment step.
#pragma once

#include <Eigen/Geometry>

#include "breast_tumour_registration/base/types.h"

namespace btr {

using Rigid = Eigen::Isometry3d;

/// R, t minimizing sum_i |R source_i + t - target_i|^2 (rows are corresponding points).
/// Throws InputError for fewer than 3 pairs, NaN points, or collinear points.
Rigid kabsch(const Points& source, const Points& target);

/// Applies T to every row.
Points transform_points(const Rigid& T, const Points& P);
SurfaceMesh transform_surface(const Rigid& T, const SurfaceMesh& s);

/// Rotation angle of T [rad] and translation length [m].
double rotation_angle(const Rigid& T);

/// The transform with this translation [m] and rotation R = Rz(yaw) Ry(pitch) Rx(roll)
/// (roll_pitch_yaw [rad], fixed axes X then Y then Z; ROS's RPY convention).
Rigid rigid_from_rpy(const Vec3& translation, const Vec3& roll_pitch_yaw);

/// A motion xi = (omega [rad], tau [m]) as a transform: p -> R(omega) p + tau, R(omega) the
/// rotation by |omega| about omega (for the small motions of a pose's uncertainty, where this
/// is exp(xi) to first order); motion_of is its inverse.
Rigid rigid_from_motion(const Vec6& xi);
Vec6 motion_of(const Rigid& T);

/// Largest distance between A p and B p over the rows p of P [m]; 0 for no rows.
double max_displacement(const Rigid& A, const Rigid& B, const Points& P);

}  // namespace btr
