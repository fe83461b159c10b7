#include "breast_tumour_registration/geometry/surface_projector.h"

#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_types.h>

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <map>
#include <vector>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/geometry/closest_point.h"
#include "breast_tumour_registration/geometry/vertex_normals.h"

namespace btr {
namespace {

class MeshProjector : public SurfaceProjector {
 public:
  MeshProjector(const SurfaceMesh& m, MeshNormals normals) : cp_(m.V, m.F), V_(m.V), F_(m.F), border_(m.F.rows(), 0) {
    if (normals == MeshNormals::Interpolated) vertex_normals_ = vertex_normals(m);
    // Border edges: used by one triangle only. border_[f] bit k: the edge opposite corner k.
    std::map<std::pair<int, int>, int> uses;
    const auto edge = [&](Eigen::Index f, int k) {
      const int a = F_(f, (k + 1) % 3), b = F_(f, (k + 2) % 3);
      return std::make_pair(std::min(a, b), std::max(a, b));
    };
    for (Eigen::Index f = 0; f < F_.rows(); ++f)
      for (int k = 0; k < 3; ++k) ++uses[edge(f, k)];
    for (Eigen::Index f = 0; f < F_.rows(); ++f)
      for (int k = 0; k < 3; ++k)
        if (uses[edge(f, k)] == 1) border_[f] |= static_cast<unsigned char>(1 << k);
  }
  Projection project(const Vec3& p) const override {
    const ClosestPoint c = cp_.query(p);
    Projection out{c.point, cp_.face_normal(c.face), c.distance, false};
    if (vertex_normals_.rows()) {
      Vec3 n = Vec3::Zero();
      for (int k = 0; k < 3; ++k) n += c.barycentric[k] * vertex_normals_.row(F_(c.face, k)).transpose();
      // Oriented as the face (vertex normals of an inconsistently oriented surface may not be);
      // a blend that cancels out (a fold's crease) keeps the face normal.
      if (n.dot(out.normal) < 0) n = -n;
      const double len = n.norm();
      if (len > 1e-6) out.normal = n / len;
    }
    if (border_[c.face]) {
      for (int k = 0; k < 3 && !out.on_boundary; ++k) {
        if (!(border_[c.face] & (1 << k))) continue;
        const Vec3 a = V_.row(F_(c.face, (k + 1) % 3)), b = V_.row(F_(c.face, (k + 2) % 3));
        const double len2 = (b - a).squaredNorm();
        const double t = len2 > 0 ? std::clamp((c.point - a).dot(b - a) / len2, 0.0, 1.0) : 0.0;
        out.on_boundary = (a + t * (b - a) - c.point).squaredNorm() <= 1e-12 * std::max(len2, 1e-12);
      }
    }
    return out;
  }

 private:
  SurfaceClosestPoint cp_;
  Points V_;
  Triangles F_;
  std::vector<unsigned char> border_;
  Points vertex_normals_;  // #V by 3 for MeshNormals::Interpolated, else empty
};

class CloudProjector : public SurfaceProjector {
 public:
  CloudProjector(const Points& P, int k) : k_(k) {
    if (!P.allFinite()) throw InputError("supine point cloud has NaN or infinite points");
    if (P.rows() < k + 1) throw InputError("supine point cloud has fewer than " + std::to_string(k + 1) + " points");
    cloud_.reset(new pcl::PointCloud<pcl::PointXYZ>);
    cloud_->resize(P.rows());
    for (Eigen::Index i = 0; i < P.rows(); ++i) (*cloud_)[i] = pcl::PointXYZ(P(i, 0), P(i, 1), P(i, 2));
    tree_.setInputCloud(cloud_);
    // Normals once per point, from the PCA of its neighbourhood.
    normals_.resize(P.rows());
    std::vector<int> idx(k);
    std::vector<float> d2(k);
    for (Eigen::Index i = 0; i < P.rows(); ++i) {
      tree_.nearestKSearch((*cloud_)[i], k, idx, d2);
      Vec3 mean = Vec3::Zero();
      for (int j : idx) mean += P.row(j).transpose();
      mean /= k;
      Mat3 C = Mat3::Zero();
      for (int j : idx) {
        const Vec3 d = P.row(j).transpose() - mean;
        C += d * d.transpose();
      }
      normals_[i] = Eigen::SelfAdjointEigenSolver<Mat3>(C).eigenvectors().col(0);
    }
    points_ = P;
  }
  Projection project(const Vec3& p) const override {
    std::vector<int> idx(1);
    std::vector<float> d2(1);
    tree_.nearestKSearch(pcl::PointXYZ(p.x(), p.y(), p.z()), 1, idx, d2);
    const Vec3 q = points_.row(idx[0]).transpose();
    const Vec3& n = normals_[idx[0]];
    // The closest point of the local tangent plane: smoother than the nearest sample.
    const Vec3 on_plane = p - (p - q).dot(n) * n;
    return {on_plane, n, (p - on_plane).norm()};
  }

 private:
  int k_;
  Points points_;
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud_;
  pcl::KdTreeFLANN<pcl::PointXYZ> tree_;
  std::vector<Vec3> normals_;
};

}  // namespace

std::unique_ptr<SurfaceProjector> make_mesh_projector(const SurfaceMesh& mesh, MeshNormals normals) {
  return std::make_unique<MeshProjector>(mesh, normals);
}

std::unique_ptr<SurfaceProjector> make_cloud_projector(const Points& cloud, int neighbours) {
  return std::make_unique<CloudProjector>(cloud, neighbours);
}

}  // namespace btr
