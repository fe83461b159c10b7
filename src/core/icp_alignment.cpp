#include "breast_tumour_registration/core/icp_alignment.h"

#include <pcl/features/normal_3d_omp.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_types.h>
#include <pcl/registration/correspondence_rejection_median_distance.h>
#include <pcl/registration/icp.h>

#include <chrono>
#include <cmath>

#include "breast_tumour_registration/core/errors.h"

namespace btr {
namespace {
using Cloud = pcl::PointCloud<pcl::PointNormal>;

Cloud::Ptr to_cloud(const Points& P, const IcpOptions& opt, const char* what) {
  if (P.rows() == 0) throw InputError(std::string("ICP: the ") + what + " cloud is empty");
  if (!P.allFinite()) throw InputError(std::string("ICP: the ") + what + " cloud has NaN coordinates");
  pcl::PointCloud<pcl::PointXYZ>::Ptr xyz(new pcl::PointCloud<pcl::PointXYZ>);
  xyz->resize(P.rows());
  for (Eigen::Index i = 0; i < P.rows(); ++i) (*xyz)[i] = pcl::PointXYZ(P(i, 0), P(i, 1), P(i, 2));
  if (opt.voxel_size > 0) {
    pcl::VoxelGrid<pcl::PointXYZ> grid;
    grid.setInputCloud(xyz);
    grid.setLeafSize(opt.voxel_size, opt.voxel_size, opt.voxel_size);
    pcl::PointCloud<pcl::PointXYZ>::Ptr down(new pcl::PointCloud<pcl::PointXYZ>);
    grid.filter(*down);
    xyz = down;
  }
  if (xyz->size() < 6) throw InputError(std::string("ICP: the ") + what + " cloud has fewer than 6 points after downsampling");
  pcl::NormalEstimationOMP<pcl::PointXYZ, pcl::PointNormal> ne;
  ne.setNumberOfThreads(0);
  ne.setInputCloud(xyz);
  ne.setKSearch(std::min<int>(opt.normal_neighbours, static_cast<int>(xyz->size()) - 1));
  Cloud::Ptr out(new Cloud);
  ne.compute(*out);
  for (size_t i = 0; i < xyz->size(); ++i) {
    (*out)[i].x = (*xyz)[i].x;
    (*out)[i].y = (*xyz)[i].y;
    (*out)[i].z = (*xyz)[i].z;
  }
  // Planar neighbourhoods can give NaN normals at borders; drop those points.
  Cloud::Ptr clean(new Cloud);
  for (const auto& p : *out)
    if (std::isfinite(p.normal_x) && std::isfinite(p.normal_y) && std::isfinite(p.normal_z)) clean->push_back(p);
  return clean;
}

}  // namespace

IcpResult align_icp(const Points& source, const Points& target, const Rigid& initial, const IcpOptions& opt) {
  const auto t0 = std::chrono::steady_clock::now();
  if (!(opt.max_correspondence_distance > 0) || opt.max_iterations < 1)
    throw InputError("ICP: max_correspondence_distance must be positive and max_iterations >= 1");
  const Cloud::Ptr src = to_cloud(source, opt, "source"), tgt = to_cloud(target, opt, "target");
  IcpResult r;
  Eigen::Matrix4f guess = initial.matrix().cast<float>();
  // Coarse pass (wide radius, captures large offsets), then the fine pass.
  for (const double radius : {opt.coarse_correspondence_distance, opt.max_correspondence_distance}) {
    if (radius <= 0) continue;
    pcl::IterativeClosestPointWithNormals<pcl::PointNormal, pcl::PointNormal> icp;
    icp.setInputSource(src);
    icp.setInputTarget(tgt);
    icp.setMaxCorrespondenceDistance(radius);
    icp.setMaximumIterations(opt.max_iterations);
    icp.setTransformationEpsilon(opt.transformation_epsilon);
    icp.setEuclideanFitnessEpsilon(1e-14);
    pcl::registration::CorrespondenceRejectorMedianDistance::Ptr rej(new pcl::registration::CorrespondenceRejectorMedianDistance);
    rej->setMedianFactor(opt.median_factor);
    icp.addCorrespondenceRejector(rej);
    Cloud aligned;
    icp.align(aligned, guess);
    r.converged = icp.hasConverged();
    r.iterations += icp.nr_iterations_;
    if (!r.converged) break;
    guess = icp.getFinalTransformation();
  }
  r.transform.matrix() = guess.cast<double>();
  // Re-orthonormalize the float rotation.
  Eigen::JacobiSVD<Mat3> svd(r.transform.linear(), Eigen::ComputeFullU | Eigen::ComputeFullV);
  r.transform.linear() = svd.matrixU() * svd.matrixV().transpose();
  // Inlier RMS and overlap measured in double precision on the downsampled clouds.
  pcl::KdTreeFLANN<pcl::PointNormal> tree;
  tree.setInputCloud(tgt);
  std::vector<int> idx(1);
  std::vector<float> d2(1);
  double sq = 0;
  int inliers = 0;
  for (const auto& p : *src) {
    const Vec3 q = r.transform * Vec3(p.x, p.y, p.z);
    pcl::PointNormal s;
    s.x = q.x(); s.y = q.y(); s.z = q.z();
    if (tree.nearestKSearch(s, 1, idx, d2) < 1) continue;
    const auto& t = (*tgt)[idx[0]];
    const double dist = std::abs((q - Vec3(t.x, t.y, t.z)).dot(Vec3(t.normal_x, t.normal_y, t.normal_z)));
    if (std::sqrt(d2[0]) > opt.max_correspondence_distance) continue;
    sq += dist * dist;
    ++inliers;
  }
  r.overlap = src->empty() ? 0.0 : static_cast<double>(inliers) / src->size();
  r.inlier_rms = inliers ? std::sqrt(sq / inliers) : std::numeric_limits<double>::infinity();
  if (!r.converged) r.message = "ICP did not converge";
  else if (r.overlap < opt.min_overlap) r.message = "ICP overlap " + std::to_string(r.overlap) + " below " + std::to_string(opt.min_overlap);
  else if (r.inlier_rms > opt.max_inlier_rms) r.message = "ICP inlier RMS " + std::to_string(r.inlier_rms * 1e3) + " mm above the bound";
  else {
    r.accepted = true;
    r.message = "ICP accepted";
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace btr
