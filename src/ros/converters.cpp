#include "breast_tumour_registration/ros/converters.h"

#include <sensor_msgs/point_cloud2_iterator.h>
#include <tf2_eigen/tf2_eigen.h>

#include <Eigen/Geometry>

#include <cmath>
#include <cstring>
#include <limits>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/geometry/confidence_ellipsoid.h"

namespace btr::ros_conv {

CloudPoints from_cloud(const sensor_msgs::PointCloud2& msg, bool keep_nan) {
  const sensor_msgs::PointField* f[3] = {nullptr, nullptr, nullptr};
  for (const auto& field : msg.fields) {
    if (field.name == "x") f[0] = &field;
    if (field.name == "y") f[1] = &field;
    if (field.name == "z") f[2] = &field;
  }
  if (!f[0] || !f[1] || !f[2]) throw InputError("point cloud has no x, y, z fields");
  // Every read below stays inside msg.data: the layout is checked in 64-bit arithmetic first
  // (a malformed cloud from any publisher must not crash the node).
  const uint64_t point_step = msg.point_step, row_step = msg.row_step, width = msg.width, height = msg.height;
  for (const auto* p : f) {
    if (p->datatype != sensor_msgs::PointField::FLOAT32 && p->datatype != sensor_msgs::PointField::FLOAT64)
      throw InputError("point cloud field '" + p->name + "' is not FLOAT32 or FLOAT64");
    const uint64_t size = p->datatype == sensor_msgs::PointField::FLOAT32 ? 4 : 8;
    if (p->count < 1 || uint64_t{p->offset} + size > point_step)
      throw InputError("point cloud field '" + p->name + "' (offset " + std::to_string(p->offset) +
                       ") does not fit in a point of " + std::to_string(point_step) + " bytes");
  }
  if (msg.is_bigendian) throw InputError("big-endian point clouds are not supported");
  if (width * point_step > row_step)
    throw InputError("point cloud row_step " + std::to_string(row_step) + " is shorter than width x point_step (" +
                     std::to_string(width * point_step) + ")");
  if (width > 0 && height > 0 && (height - 1) * row_step + width * point_step > msg.data.size())
    throw InputError("point cloud data (" + std::to_string(msg.data.size()) + " bytes) is shorter than its layout (" +
                     std::to_string(height) + " rows of " + std::to_string(row_step) + " bytes)");
  const size_t n = static_cast<size_t>(width * height);
  CloudPoints out;
  out.width = static_cast<int>(msg.width);
  out.height = static_cast<int>(msg.height);
  out.points.resize(0, 3);
  // No points: done before any pointer into msg.data is formed (an empty buffer has none;
  // fuzz finding, test/fuzz/corpus/fuzz_pointcloud2/regression_zero_width).
  if (n == 0) return out;
  out.organized = msg.height > 1;
  const bool organized_keep = keep_nan && out.organized;
  out.points.resize(static_cast<Eigen::Index>(n), 3);
  double* dst = out.points.data();  // row-major: x y z of each point in a row
  const double nan = std::numeric_limits<double>::quiet_NaN();
  const bool all_float = f[0]->datatype == sensor_msgs::PointField::FLOAT32 &&
                         f[1]->datatype == sensor_msgs::PointField::FLOAT32 &&
                         f[2]->datatype == sensor_msgs::PointField::FLOAT32;
  Eigen::Index k = 0;
  for (uint32_t r = 0; r < msg.height; ++r) {
    const uint8_t* row = msg.data.data() + static_cast<size_t>(r) * msg.row_step;
    for (uint32_t c = 0; c < msg.width; ++c) {
      const uint8_t* base = row + static_cast<size_t>(c) * msg.point_step;
      double v[3];
      for (int i = 0; i < 3; ++i) {
        if (all_float || f[i]->datatype == sensor_msgs::PointField::FLOAT32) {
          float x;
          std::memcpy(&x, base + f[i]->offset, 4);
          v[i] = x;
        } else {
          std::memcpy(&v[i], base + f[i]->offset, 8);
        }
      }
      const bool finite = std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]);
      out.finite += finite;
      if (!finite && !organized_keep) continue;
      double* o = dst + 3 * k++;
      o[0] = finite ? v[0] : nan;
      o[1] = finite ? v[1] : nan;
      o[2] = finite ? v[2] : nan;
    }
  }
  out.points.conservativeResize(k, 3);
  if (!organized_keep) out.organized = false;
  return out;
}

sensor_msgs::PointCloud2 to_cloud(const Points& P, int width, int height, const std::string& frame_id) {
  sensor_msgs::PointCloud2 msg;
  msg.header.frame_id = frame_id;
  sensor_msgs::PointCloud2Modifier mod(msg);
  mod.setPointCloud2FieldsByString(1, "xyz");
  msg.height = height;
  msg.width = width;
  mod.resize(static_cast<size_t>(width) * height);
  msg.height = height;
  msg.width = width;
  msg.row_step = msg.point_step * width;
  msg.is_dense = false;
  if (P.rows() == 0) return msg;  // the iterators read data.front(): undefined on an empty cloud (UBSan)
  sensor_msgs::PointCloud2Iterator<float> x(msg, "x"), y(msg, "y"), z(msg, "z");
  for (Eigen::Index i = 0; i < P.rows(); ++i, ++x, ++y, ++z) {
    *x = static_cast<float>(P(i, 0));
    *y = static_cast<float>(P(i, 1));
    *z = static_cast<float>(P(i, 2));
  }
  return msg;
}

shape_msgs::Mesh to_mesh(const SurfaceMesh& s) {
  shape_msgs::Mesh m;
  m.vertices.resize(s.V.rows());
  for (Eigen::Index i = 0; i < s.V.rows(); ++i) {
    m.vertices[i].x = s.V(i, 0);
    m.vertices[i].y = s.V(i, 1);
    m.vertices[i].z = s.V(i, 2);
  }
  m.triangles.resize(s.F.rows());
  for (Eigen::Index f = 0; f < s.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) m.triangles[f].vertex_indices[k] = static_cast<uint32_t>(s.F(f, k));
  return m;
}

SurfaceMesh from_mesh(const shape_msgs::Mesh& m) {
  SurfaceMesh s;
  s.V.resize(m.vertices.size(), 3);
  for (size_t i = 0; i < m.vertices.size(); ++i) s.V.row(i) << m.vertices[i].x, m.vertices[i].y, m.vertices[i].z;
  s.F.resize(m.triangles.size(), 3);
  for (size_t f = 0; f < m.triangles.size(); ++f)
    for (int k = 0; k < 3; ++k) {
      if (m.triangles[f].vertex_indices[k] >= m.vertices.size()) throw InputError("mesh triangle index out of range");
      s.F(f, k) = static_cast<int>(m.triangles[f].vertex_indices[k]);
    }
  return s;
}

namespace {
// A marker of `type` with the identity pose, unit scale and the colour given.
visualization_msgs::Marker new_marker(int type, const std::string& frame_id, const std::string& ns, int id, float r, float g,
                                      float b, float a) {
  visualization_msgs::Marker mk;
  mk.header.frame_id = frame_id;
  mk.ns = ns;
  mk.id = id;
  mk.type = type;
  mk.action = visualization_msgs::Marker::ADD;
  mk.pose.orientation.w = 1.0;
  mk.scale.x = mk.scale.y = mk.scale.z = 1.0;
  mk.color.r = r;
  mk.color.g = g;
  mk.color.b = b;
  mk.color.a = a;
  return mk;
}
}  // namespace

visualization_msgs::Marker to_marker(const SurfaceMesh& s, const std::string& frame_id, const std::string& ns, int id,
                                     float r, float g, float b, float a) {
  visualization_msgs::Marker mk = new_marker(visualization_msgs::Marker::TRIANGLE_LIST, frame_id, ns, id, r, g, b, a);
  mk.points.reserve(3 * s.F.rows());
  for (Eigen::Index f = 0; f < s.F.rows(); ++f)
    for (int k = 0; k < 3; ++k) {
      geometry_msgs::Point p;
      p.x = s.V(s.F(f, k), 0);
      p.y = s.V(s.F(f, k), 1);
      p.z = s.V(s.F(f, k), 2);
      mk.points.push_back(p);
    }
  return mk;
}

visualization_msgs::Marker to_ellipsoid_marker(const Vec3& centre, const Mat3& cov, const std::string& frame_id,
                                               const std::string& ns, int id, float r, float g, float b, float a) {
  const Ellipsoid95 e = ellipsoid_95(cov);
  const Eigen::Quaterniond q(e.axes);
  visualization_msgs::Marker mk = new_marker(visualization_msgs::Marker::SPHERE, frame_id, ns, id, r, g, b, a);
  mk.pose.position.x = centre.x();
  mk.pose.position.y = centre.y();
  mk.pose.position.z = centre.z();
  mk.pose.orientation.w = q.w();
  mk.pose.orientation.x = q.x();
  mk.pose.orientation.y = q.y();
  mk.pose.orientation.z = q.z();
  mk.scale.x = 2 * e.semi_axes[0];
  mk.scale.y = 2 * e.semi_axes[1];
  mk.scale.z = 2 * e.semi_axes[2];
  return mk;
}

geometry_msgs::Transform to_transform(const Rigid& T) { return tf2::eigenToTransform(T).transform; }

Rigid from_transform(const geometry_msgs::Transform& t) {
  // tf2_eigen takes the quaternion as it is; a publisher's may be off unit length by rounding.
  const double n = std::sqrt(t.rotation.w * t.rotation.w + t.rotation.x * t.rotation.x + t.rotation.y * t.rotation.y +
                             t.rotation.z * t.rotation.z);
  if (!std::isfinite(n) || n < 1e-9) throw InputError("transform has a zero or non-finite rotation quaternion");
  geometry_msgs::Transform u = t;
  u.rotation.w /= n;
  u.rotation.x /= n;
  u.rotation.y /= n;
  u.rotation.z /= n;
  return tf2::transformToEigen(u);
}

}  // namespace btr::ros_conv
