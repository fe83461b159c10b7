// Small static converters between ROS messages and the core library's types. No state,
// no node handle: unit-tested without a master.
#pragma once

#include <geometry_msgs/Point.h>
#include <geometry_msgs/TransformStamped.h>
#include <sensor_msgs/PointCloud2.h>
#include <shape_msgs/Mesh.h>
#include <visualization_msgs/Marker.h>

#include <string>

#include "breast_tumour_registration/base/types.h"
#include "breast_tumour_registration/geometry/rigid_transform.h"

namespace btr::ros_conv {

struct CloudPoints {
  Points points;        ///< one row per pixel when organized (NaN kept), else finite points only
  int width = 0, height = 0;
  bool organized = false;
  long finite = 0;      ///< number of finite points
};

/// Reads x, y, z (FLOAT32 or FLOAT64) of a PointCloud2. Not pcl::fromROSMsg: that reads past
/// the end of a cloud whose data is shorter than its layout and turns FLOAT64 fields into
/// zeros (measured, bench/probes/pcl_from_ros_msg.cpp); every cloud here comes from outside. `keep_nan` keeps the organized
/// layout (NaN rows); otherwise NaN and infinite points are dropped. Throws InputError for
/// a cloud without x, y, z fields or with inconsistent sizes.
CloudPoints from_cloud(const sensor_msgs::PointCloud2& msg, bool keep_nan);

/// An organized XYZ FLOAT32 PointCloud2 (NaN rows stay NaN) in `frame_id`.
sensor_msgs::PointCloud2 to_cloud(const Points& P, int width, int height, const std::string& frame_id);

shape_msgs::Mesh to_mesh(const SurfaceMesh& s);
SurfaceMesh from_mesh(const shape_msgs::Mesh& m);

/// A TRIANGLE_LIST marker of the surface.
visualization_msgs::Marker to_marker(const SurfaceMesh& s, const std::string& frame_id, const std::string& ns, int id,
                                     float r, float g, float b, float a);

/// The 95 % region of a point with Gaussian covariance `cov` [m^2] about `centre`: a SPHERE
/// marker scaled and turned into the ellipsoid whose axes are 2 sqrt(chi2_3(0.95) lambda_i)
/// along the eigenvectors (chi2_3(0.95) = 7.815).
visualization_msgs::Marker to_ellipsoid_marker(const Vec3& centre, const Mat3& cov, const std::string& frame_id,
                                               const std::string& ns, int id, float r, float g, float b, float a);

/// Through tf2_eigen; from_transform normalizes the quaternion and throws InputError for a
/// zero or non-finite one.
geometry_msgs::Transform to_transform(const Rigid& T);
Rigid from_transform(const geometry_msgs::Transform& t);

}  // namespace btr::ros_conv
