// Closed triangle surfaces of simple shapes used by the synthetic phantom.
#pragma once

#include "breast_tumour_registration/core/types.h"

namespace btr {

/// Half ellipsoid with semi-axes (a, b, c): dome z >= 0 over the flat elliptic base z = 0
/// (the chest wall), outward oriented. `rings` is the number of rings between apex and
/// rim (and between the base centre and rim); ring k has 6k vertices.
SurfaceMesh make_half_ellipsoid(double a, double b, double c, int rings);

/// Icosphere of the given radius [m] around centre, outward oriented.
SurfaceMesh make_icosphere(const Vec3& centre, double radius, int subdivisions);

/// Flat elliptic annulus in the plane z = z0 between the ellipse (a, b) scaled by 1 and by
/// (1 + width / min(a, b)); normal +z. `segments` points around.
SurfaceMesh make_elliptic_ring(double a, double b, double width, int segments, double z0 = 0.0);

/// Point on the half-ellipsoid dome at polar angle theta from the apex and azimuth phi [rad].
Vec3 half_ellipsoid_point(double a, double b, double c, double theta, double phi);

}  // namespace btr
