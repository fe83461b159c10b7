#include "breast_tumour_registration/geometry/closest_point.h"

#include <CGAL/AABB_traits.h>
#include <CGAL/AABB_tree.h>
#include <CGAL/AABB_triangle_primitive.h>
#include <CGAL/Simple_cartesian.h>

#include <vector>

#include "breast_tumour_registration/base/errors.h"

namespace btr {
namespace {
using K = CGAL::Simple_cartesian<double>;
using Triangle = K::Triangle_3;
using Iterator = std::vector<Triangle>::const_iterator;
using Primitive = CGAL::AABB_triangle_primitive<K, Iterator>;
using Tree = CGAL::AABB_tree<CGAL::AABB_traits<K, Primitive>>;

K::Point_3 to_cgal(const Vec3& p) { return {p.x(), p.y(), p.z()}; }
}  // namespace

struct SurfaceClosestPoint::Impl {
  Points V;
  Triangles F;
  std::vector<Triangle> triangles;
  Tree tree;
};

SurfaceClosestPoint::SurfaceClosestPoint(const Points& V, const Triangles& F) : impl_(std::make_unique<Impl>()) {
  if (F.rows() == 0) throw InputError("closest-point query needs a surface with at least one face");
  impl_->V = V;
  impl_->F = F;
  impl_->triangles.reserve(F.rows());
  for (Eigen::Index f = 0; f < F.rows(); ++f)
    impl_->triangles.emplace_back(to_cgal(V.row(F(f, 0))), to_cgal(V.row(F(f, 1))), to_cgal(V.row(F(f, 2))));
  impl_->tree.insert(impl_->triangles.cbegin(), impl_->triangles.cend());
  impl_->tree.build();
  impl_->tree.accelerate_distance_queries();
}

SurfaceClosestPoint::~SurfaceClosestPoint() = default;
SurfaceClosestPoint::SurfaceClosestPoint(SurfaceClosestPoint&&) noexcept = default;
SurfaceClosestPoint& SurfaceClosestPoint::operator=(SurfaceClosestPoint&&) noexcept = default;

ClosestPoint SurfaceClosestPoint::query(const Vec3& p) const {
  const auto hit = impl_->tree.closest_point_and_primitive(to_cgal(p));
  ClosestPoint r;
  r.point = Vec3(hit.first.x(), hit.first.y(), hit.first.z());
  r.face = static_cast<int>(hit.second - impl_->triangles.cbegin());
  r.distance = (r.point - p).norm();
  // Barycentric coordinates of the closest point in its triangle (clamped for round-off).
  const Vec3 a = impl_->V.row(impl_->F(r.face, 0)), b = impl_->V.row(impl_->F(r.face, 1)),
             c = impl_->V.row(impl_->F(r.face, 2));
  const Vec3 v0 = b - a, v1 = c - a, v2 = r.point - a;
  const double d00 = v0.dot(v0), d01 = v0.dot(v1), d11 = v1.dot(v1), d20 = v2.dot(v0), d21 = v2.dot(v1);
  const double den = d00 * d11 - d01 * d01;
  double v = den > 0 ? (d11 * d20 - d01 * d21) / den : 0.0;
  double w = den > 0 ? (d00 * d21 - d01 * d20) / den : 0.0;
  v = std::clamp(v, 0.0, 1.0);
  w = std::clamp(w, 0.0, 1.0 - v);
  r.barycentric = Vec3(1.0 - v - w, v, w);
  return r;
}

Vec3 SurfaceClosestPoint::face_normal(int f) const {
  const Vec3 a = impl_->V.row(impl_->F(f, 0)), b = impl_->V.row(impl_->F(f, 1)), c = impl_->V.row(impl_->F(f, 2));
  return (b - a).cross(c - a).normalized();
}

}  // namespace btr
