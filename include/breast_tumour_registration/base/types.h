// Basic matrix types of the core library. Everything inside the library is SI
// (metres, pascals, kg/m^3, newtons); files in millimetres are converted once in mesh_io.
#pragma once

#include <Eigen/Core>
#include <Eigen/Dense>

namespace btr {

/// #V by 3 vertex positions, row-major so that a Points matrix maps onto the
/// 3#V degree-of-freedom vector [x0 y0 z0 x1 y1 z1 ...] without a copy.
using Points = Eigen::Matrix<double, Eigen::Dynamic, 3, Eigen::RowMajor>;
/// #F by 3 triangle vertex indices.
using Triangles = Eigen::Matrix<int, Eigen::Dynamic, 3, Eigen::RowMajor>;
/// #T by 4 tetrahedron vertex indices (positive orientation: (v1-v0).((v2-v0)x(v3-v0)) > 0).
using Tetrahedra = Eigen::Matrix<int, Eigen::Dynamic, 4, Eigen::RowMajor>;

using Vec3 = Eigen::Vector3d;
using Mat3 = Eigen::Matrix3d;
using Vec6 = Eigen::Matrix<double, 6, 1>;
using Mat6 = Eigen::Matrix<double, 6, 6>;
using Vec9 = Eigen::Matrix<double, 9, 1>;
using Mat9 = Eigen::Matrix<double, 9, 9>;
using Vec12 = Eigen::Matrix<double, 12, 1>;
using Mat12 = Eigen::Matrix<double, 12, 12>;
using Mat9x12 = Eigen::Matrix<double, 9, 12>;

/// A closed (or open, for scans) triangle surface.
struct SurfaceMesh {
  Points V;     ///< #V by 3 positions [m]
  Triangles F;  ///< #F by 3 indices into V
};

/// A tetrahedral volume mesh.
struct TetMesh {
  Points V;      ///< #V by 3 positions [m]
  Tetrahedra T;  ///< #T by 4 indices into V
};

/// Flat view of a Points matrix as the 3#V DOF vector.
inline Eigen::Map<Eigen::VectorXd> as_vector(Points& V) {
  return Eigen::Map<Eigen::VectorXd>(V.data(), V.size());
}
inline Eigen::Map<const Eigen::VectorXd> as_vector(const Points& V) {
  return Eigen::Map<const Eigen::VectorXd>(V.data(), V.size());
}
/// Points view of a 3#V DOF vector.
inline Eigen::Map<const Points> as_points(const Eigen::VectorXd& x) {
  return Eigen::Map<const Points>(x.data(), x.size() / 3, 3);
}

}  // namespace btr
