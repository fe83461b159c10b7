#include "breast_tumour_registration/simulation/depth_camera.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <cmath>
#include <limits>
#include <optional>

#include "breast_tumour_registration/base/errors.h"

namespace btr {
namespace {
using K = CGAL::Simple_cartesian<double>;
using Triangle = K::Triangle_3;
using Iterator = std::vector<Triangle>::const_iterator;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, CGAL::AABB_triangle_primitive<K, Iterator>>>;
}  // namespace

Points render_depth(const std::vector<const SurfaceMesh*>& surfaces, const PinholeCamera& cam, const Rigid& camera_to_world) {
  if (cam.width < 1 || cam.height < 1 || !(cam.fx > 0) || !(cam.fy > 0)) throw InputError("depth camera: bad intrinsics");
  std::vector<Triangle> tris;
  for (const SurfaceMesh* s : surfaces)
    for (Eigen::Index f = 0; f < s->F.rows(); ++f) {
      auto p = [&](int k) { return K::Point_3(s->V(s->F(f, k), 0), s->V(s->F(f, k), 1), s->V(s->F(f, k), 2)); };
      tris.emplace_back(p(0), p(1), p(2));
    }
  if (tris.empty()) throw InputError("depth camera: nothing to render");
  Tree tree(tris.cbegin(), tris.cend());
  tree.build();
  const Vec3 origin = camera_to_world.translation();
  const Rigid world_to_camera = camera_to_world.inverse();
  Points cloud(static_cast<Eigen::Index>(cam.width) * cam.height, 3);
  const double nan = std::numeric_limits<double>::quiet_NaN();
#pragma omp parallel for schedule(dynamic, 8)
  for (int v = 0; v < cam.height; ++v)
    for (int u = 0; u < cam.width; ++u) {
      const Vec3 d_cam((u - cam.cx) / cam.fx, (v - cam.cy) / cam.fy, 1.0);
      const Vec3 d = camera_to_world.linear() * d_cam;
      const K::Ray_3 ray(K::Point_3(origin.x(), origin.y(), origin.z()), K::Vector_3(d.x(), d.y(), d.z()));
      const auto hit = tree.first_intersection(ray);
      Eigen::RowVector3d out(nan, nan, nan);
      if (hit) {
        if (const K::Point_3* p = boost::get<K::Point_3>(&hit->first)) {
          const Vec3 pc = world_to_camera * Vec3(p->x(), p->y(), p->z());
          if (pc.z() >= cam.min_range && pc.z() <= cam.max_range) out = pc.transpose();
        }
      }
      cloud.row(static_cast<Eigen::Index>(v) * cam.width + u) = out;
    }
  return cloud;
}

void add_depth_noise(Points& cloud, double sigma, std::mt19937& rng) {
  std::normal_distribution<double> n(0.0, sigma);
  for (Eigen::Index i = 0; i < cloud.rows(); ++i) {
    if (!cloud.row(i).allFinite()) continue;
    const double z = cloud(i, 2);
    cloud.row(i) *= (z + n(rng)) / z;  // along the pixel ray
  }
}

Rigid look_at(const Vec3& eye, const Vec3& target, const Vec3& up) {
  const Vec3 z = (target - eye).normalized();
  Vec3 x = z.cross(up);
  if (x.norm() < 1e-9) throw InputError("look_at: up is parallel to the viewing direction");
  x.normalize();
  const Vec3 y = z.cross(x);  // image y points down when `up` is up
  Rigid T = Rigid::Identity();
  T.linear().col(0) = x;
  T.linear().col(1) = y;
  T.linear().col(2) = z;
  T.translation() = eye;
  return T;
}

}  // namespace btr
