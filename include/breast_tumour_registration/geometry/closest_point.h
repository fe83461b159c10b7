// Closest points on a triangle surface (CGAL AABB tree behind a small interface, so
// that only closest_point.cpp includes CGAL).
#pragma once

#include <memory>

#include "breast_tumour_registration/base/types.h"

namespace btr {

struct ClosestPoint {
  Vec3 point;        ///< closest point on the surface [m]
  int face = -1;     ///< triangle index
  Vec3 barycentric;  ///< weights of the triangle's three vertices (sum to 1, >= 0)
  double distance = 0;
};

class SurfaceClosestPoint {
 public:
  /// V #V by 3, F #F by 3. Throws InputError for an empty surface.
  SurfaceClosestPoint(const Points& V, const Triangles& F);
  ~SurfaceClosestPoint();
  SurfaceClosestPoint(SurfaceClosestPoint&&) noexcept;
  SurfaceClosestPoint& operator=(SurfaceClosestPoint&&) noexcept;

  ClosestPoint query(const Vec3& p) const;
  /// Unit normal of triangle f (right-hand rule on its vertex order).
  Vec3 face_normal(int f) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace btr
