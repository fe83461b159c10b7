#include "breast_tumour_registration/core/surface_projector.h"

#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_types.h>

#include <Eigen/Eigenvalues>
#include <vector>

#include "breast_tumour_registration/core/closest_point.h"
#include "breast_tumour_registration/core/errors.h"

namespace btr {
namespace {

class MeshProjector : public SurfaceProjector {
 public:
  explicit MeshProjector(const SurfaceMesh& m) : cp_(m.V, m.F) {}
  Projection project(const Vec3& p) const override {
    const ClosestPoint c = cp_.query(p);
    return {c.point, cp_.face_normal(c.face), c.distance};
  }

 private:
  SurfaceClosestPoint cp_;
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

std::unique_ptr<SurfaceProjector> make_mesh_projector(const SurfaceMesh& mesh) {
  return std::make_unique<MeshProjector>(mesh);
}

std::unique_ptr<SurfaceProjector> make_cloud_projector(const Points& cloud, int neighbours) {
  return std::make_unique<CloudProjector>(cloud, neighbours);
}

}  // namespace btr
