// Closed triangle surfaces of simple shapes used by the synthetic phantom.
#pragma once

#include "breast_tumour_registration/base/types.h"

namespace btr {

/// Half ellipsoid with semi-axes (a, b, c): dome z >= 0 over the flat elliptic base z = 0
/// (the chest wall), outward oriented. `rings` is the number of rings between apex and
/// rim (and between the base centre and rim); ring k has 6k vertices.
SurfaceMesh make_half_ellipsoid(double a, double b, double c, int rings);

/// Icosphere of the given radius [m] around centre, outward oriented.
SurfaceMesh make_icosphere(const Vec3& centre, double radius, int subdivisions);

/// Ring of chest skin around the elliptic breast base (a, b) in z = 0, `width` wide. It
/// curves away from the breast like a rib cage, z = -d^2 (1 + 0.5 cos 2 phi) / (2 R) at
/// distance d beyond the rim, so that it is doubly curved and not rotationally symmetric:
/// rigid alignment (ICP) on it then determines all six degrees of freedom, which a flat
/// ring would not. R = `curvature_radius` [m]; normal roughly +z.
SurfaceMesh make_chest_ring(double a, double b, double width, int segments, double curvature_radius = 0.12);

/// Point on the half-ellipsoid dome at polar angle theta from the apex and azimuth phi [rad].
Vec3 half_ellipsoid_point(double a, double b, double c, double theta, double phi);

}  // namespace btr
