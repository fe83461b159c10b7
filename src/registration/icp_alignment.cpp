#include "breast_tumour_registration/registration/icp_alignment.h"

#include <pcl/features/normal_3d_omp.h>
#include <pcl/filters/voxel_grid.h>
#include <pcl/point_types.h>
#include <pcl/registration/correspondence_rejection_median_distance.h>
#include <pcl/registration/icp.h>
#include <pcl/search/kdtree.h>

#include <Eigen/Eigenvalues>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/geometry/nearest_sample_grid.h"

namespace btr {
namespace {
using Cloud = pcl::PointCloud<pcl::PointNormal>;
using Tree = pcl::search::KdTree<pcl::PointNormal>;

/// The finite-checked points of P, voxel-averaged when opt.voxel_size > 0; normals zero.
Cloud::Ptr downsampled(const Points& P, const IcpOptions& opt, const char* what) {
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
  Cloud::Ptr out(new Cloud);
  out->resize(xyz->size());
  for (size_t i = 0; i < xyz->size(); ++i) {
    pcl::PointNormal& q = (*out)[i];
    q.x = (*xyz)[i].x;
    q.y = (*xyz)[i].y;
    q.z = (*xyz)[i].z;
    q.normal_x = q.normal_y = q.normal_z = 0.f;
  }
  return out;
}

/// Downsampled points of P with normals estimated from their neighbours; points whose
/// neighbourhood gives no normal (borders) are dropped.
Cloud::Ptr with_estimated_normals(const Points& P, const IcpOptions& opt, const char* what) {
  const Cloud::Ptr pts = downsampled(P, opt, what);
  pcl::NormalEstimationOMP<pcl::PointNormal, pcl::PointNormal> ne;
  ne.setNumberOfThreads(0);
  ne.setInputCloud(pts);
  ne.setKSearch(std::min<int>(opt.normal_neighbours, static_cast<int>(pts->size()) - 1));
  Cloud normals;
  ne.compute(normals);
  Cloud::Ptr clean(new Cloud);
  for (size_t i = 0; i < pts->size(); ++i) {
    const auto& n = normals[i];
    if (!std::isfinite(n.normal_x) || !std::isfinite(n.normal_y) || !std::isfinite(n.normal_z)) continue;
    pcl::PointNormal p = (*pts)[i];
    p.normal_x = n.normal_x;
    p.normal_y = n.normal_y;
    p.normal_z = n.normal_z;
    clean->push_back(p);
  }
  return clean;
}

/// PCL correspondence estimation that asks a NearestSampleGrid instead of a kd-tree: the
/// rest of PCL's ICP (point-to-plane estimation, rejectors, convergence) is unchanged.
class GridCorrespondenceEstimation
    : public pcl::registration::CorrespondenceEstimationBase<pcl::PointNormal, pcl::PointNormal, float> {
 public:
  explicit GridCorrespondenceEstimation(std::shared_ptr<const NearestSampleGrid> grid) : grid_(std::move(grid)) {
    corr_name_ = "GridCorrespondenceEstimation";
  }

  void determineCorrespondences(pcl::Correspondences& out, double max_distance) override {
    if (!input_ || !target_) throw InputError("grid correspondences: source or target missing");
    const double max2 = max_distance * max_distance;
    out.resize(input_->size());
    size_t k = 0;
    for (size_t i = 0; i < input_->size(); ++i) {
      const auto& p = (*input_)[i];
      const int j = grid_->nearest(Vec3(p.x, p.y, p.z));
      if (j < 0) continue;
      const auto& t = (*target_)[j];
      const double d2 = (Vec3(p.x, p.y, p.z) - Vec3(t.x, t.y, t.z)).squaredNorm();
      if (d2 > max2) continue;
      out[k++] = pcl::Correspondence(static_cast<int>(i), j, static_cast<float>(d2));
    }
    out.resize(k);
  }

  /// Keeps the correspondences (i -> j) for which i is also the source point nearest to j.
  void determineReciprocalCorrespondences(pcl::Correspondences& out, double max_distance) override {
    pcl::Correspondences forward;
    determineCorrespondences(forward, max_distance);
    initComputeReciprocal();
    pcl::Indices idx(1);
    std::vector<float> d2(1);
    out.clear();
    for (const auto& c : forward)
      if (tree_reciprocal_->nearestKSearch((*target_)[c.index_match], 1, idx, d2) == 1 && idx[0] == c.index_query)
        out.push_back(c);
  }

  pcl::registration::CorrespondenceEstimationBase<pcl::PointNormal, pcl::PointNormal, float>::Ptr clone() const override {
    return std::make_shared<GridCorrespondenceEstimation>(*this);
  }

 private:
  std::shared_ptr<const NearestSampleGrid> grid_;
};

/// Point-to-plane ICP passes (coarse radius first when positive, then the fine one) of src
/// onto tgt; `tree` is tgt's prepared kd-tree or null to build one; with a `grid`,
/// correspondences come from it instead.
void run_passes(const Cloud::Ptr& src, const Cloud::Ptr& tgt, const Tree::Ptr& tree,
                const std::shared_ptr<const NearestSampleGrid>& grid, const Rigid& initial, const IcpOptions& opt,
                double coarse_radius, IcpResult& r) {
  Eigen::Matrix4f guess = initial.matrix().cast<float>();
  for (const double radius : {coarse_radius, opt.max_correspondence_distance}) {
    if (radius <= 0) continue;
    pcl::IterativeClosestPointWithNormals<pcl::PointNormal, pcl::PointNormal> icp;
    icp.setInputSource(src);
    icp.setInputTarget(tgt);
    if (tree) icp.setSearchMethodTarget(tree, true);
    if (grid) icp.setCorrespondenceEstimation(std::make_shared<GridCorrespondenceEstimation>(grid));
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
}

/// Inlier RMS (point-to-plane) and overlap in double precision, then the verdict.
/// nearest(q) gives the index of tgt's point nearest to q, or -1.
template <class Nearest>
void judge(const Cloud& src, const Cloud& tgt, const Nearest& nearest, const IcpOptions& opt, IcpResult& r) {
  double sq = 0;
  long inliers = 0;
  std::vector<Vec3> moved, normals;
  std::vector<double> residuals;
  for (const auto& p : src) {
    const Vec3 q = r.transform * Vec3(p.x, p.y, p.z);
    const int j = nearest(q);
    if (j < 0) continue;
    const auto& t = tgt[j];
    if ((q - Vec3(t.x, t.y, t.z)).norm() > opt.max_correspondence_distance) continue;
    const Vec3 n(t.normal_x, t.normal_y, t.normal_z);
    const double dist = (q - Vec3(t.x, t.y, t.z)).dot(n);
    sq += dist * dist;
    ++inliers;
    moved.push_back(q);
    normals.push_back(n);
    residuals.push_back(dist);
  }
  r.overlap = src.empty() ? 0.0 : static_cast<double>(inliers) / src.size();
  r.inlier_rms = inliers ? std::sqrt(sq / inliers) : std::numeric_limits<double>::infinity();
  Points Q(static_cast<Eigen::Index>(moved.size()), 3), N(static_cast<Eigen::Index>(moved.size()), 3);
  for (size_t i = 0; i < moved.size(); ++i) {
    Q.row(static_cast<Eigen::Index>(i)) = moved[i].transpose();
    N.row(static_cast<Eigen::Index>(i)) = normals[i].transpose();
  }
  r.pose_covariance = point_to_plane_pose_covariance(
      Q, N, Eigen::Map<const Eigen::VectorXd>(residuals.data(), static_cast<Eigen::Index>(residuals.size())),
      r.pose_covariance_note);
  if (!r.converged) r.message = "ICP did not converge";
  else if (r.overlap < opt.min_overlap) r.message = "ICP overlap " + std::to_string(r.overlap) + " below " + std::to_string(opt.min_overlap);
  else if (r.inlier_rms > opt.max_inlier_rms) r.message = "ICP inlier RMS " + std::to_string(r.inlier_rms * 1e3) + " mm above the bound";
  else {
    r.accepted = true;
    r.message = "ICP accepted";
  }
}

/// Nearest target point by kd-tree query.
struct TreeNearest {
  const Tree& tree;
  int operator()(const Vec3& q) const {
    pcl::PointNormal s;
    s.x = q.x();
    s.y = q.y();
    s.z = q.z();
    pcl::Indices idx(1);
    std::vector<float> d2(1);
    return tree.nearestKSearch(s, 1, idx, d2) < 1 ? -1 : idx[0];
  }
};

void check_options(const IcpOptions& opt) {
  if (!(opt.max_correspondence_distance > 0) || opt.max_iterations < 1)
    throw InputError("ICP: max_correspondence_distance must be positive and max_iterations >= 1");
}

}  // namespace

std::optional<Mat6> point_to_plane_pose_covariance(const Points& q, const Points& n, const Eigen::VectorXd& residuals,
                                                   std::string& note) {
  note.clear();
  const Eigen::Index m = q.rows();
  if (m < 7 || n.rows() != m || residuals.size() != m) {
    note = "the pose covariance needs at least 7 inlier pairs, got " + std::to_string(m);
    return std::nullopt;
  }
  // Whether every direction is determined is judged about the pairs' centroid with rotations
  // scaled by the region's RMS radius (both leave the rank unchanged and make the scale free).
  const Vec3 c = q.colwise().mean().transpose();
  const double radius = std::sqrt((q.rowwise() - c.transpose()).rowwise().squaredNorm().mean());
  Mat6 A = Mat6::Zero(), A_scaled = Mat6::Zero();
  for (Eigen::Index i = 0; i < m; ++i) {
    const Vec3 qi = q.row(i).transpose(), ni = n.row(i).transpose();
    Vec6 J, Js;
    J << qi.cross(ni), ni;
    Js << (qi - c).cross(ni) / std::max(radius, 1e-12), ni;
    A += J * J.transpose();
    A_scaled += Js * Js.transpose();
  }
  const Eigen::SelfAdjointEigenSolver<Mat6> es(A_scaled);
  const double top = es.eigenvalues()(5);
  if (!(top > 0) || es.eigenvalues()(0) < 1e-6 * top) {
    const Vec6 v = es.eigenvectors().col(0);
    char b[200];
    std::snprintf(b, sizeof b, "rotation (%.2f, %.2f, %.2f), translation (%.2f, %.2f, %.2f)", v(0), v(1), v(2), v(3), v(4),
                  v(5));
    note = std::string("the region does not determine the pose along the motion ") + b +
           " (about its centroid): a plane, a sphere or a surface of revolution";
    return std::nullopt;
  }
  const double sigma2 = residuals.squaredNorm() / static_cast<double>(m - 6);
  const Mat6 cov = sigma2 * A.ldlt().solve(Mat6::Identity());
  return Mat6(0.5 * (cov + cov.transpose()));
}

IcpResult align_icp(const Points& source, const Points& target, const Rigid& initial, const IcpOptions& opt) {
  const auto t0 = std::chrono::steady_clock::now();
  check_options(opt);
  const Cloud::Ptr src = with_estimated_normals(source, opt, "source"), tgt = with_estimated_normals(target, opt, "target");
  IcpResult r;
  run_passes(src, tgt, nullptr, nullptr, initial, opt, opt.coarse_correspondence_distance, r);
  Tree tree;
  tree.setInputCloud(tgt);
  judge(*src, *tgt, TreeNearest{tree}, opt, r);
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

struct IcpTarget::Impl {
  Cloud::Ptr cloud{new Cloud};
  Tree::Ptr tree{new Tree};
  std::shared_ptr<const NearestSampleGrid> grid;  // null: the kd-tree finds correspondences
};

IcpTarget::IcpTarget(const Points& points, const Points& normals, double lookup_cell, double lookup_radius)
    : impl_(std::make_unique<Impl>()) {
  if (points.rows() < 6) throw InputError("ICP target: needs at least 6 points");
  if (normals.rows() != points.rows()) throw InputError("ICP target: one normal per point is needed");
  if (!points.allFinite() || !normals.allFinite()) throw InputError("ICP target: points and normals must be finite");
  impl_->cloud->resize(points.rows());
  for (Eigen::Index i = 0; i < points.rows(); ++i) {
    const double len = normals.row(i).norm();
    if (std::abs(len - 1.0) > 1e-3) throw InputError("ICP target: normal " + std::to_string(i) + " is not of unit length");
    pcl::PointNormal& p = (*impl_->cloud)[i];
    p.x = points(i, 0);
    p.y = points(i, 1);
    p.z = points(i, 2);
    p.normal_x = normals(i, 0) / len;
    p.normal_y = normals(i, 1) / len;
    p.normal_z = normals(i, 2) / len;
  }
  impl_->tree->setInputCloud(impl_->cloud);
  if (lookup_cell > 0) impl_->grid = std::make_shared<const NearestSampleGrid>(points, lookup_cell, lookup_radius);
}
IcpTarget::~IcpTarget() = default;
IcpTarget::IcpTarget(IcpTarget&&) noexcept = default;
IcpTarget& IcpTarget::operator=(IcpTarget&&) noexcept = default;
Eigen::Index IcpTarget::size() const { return static_cast<Eigen::Index>(impl_->cloud->size()); }
double IcpTarget::lookup_radius() const { return impl_->grid ? impl_->grid->radius() : 0.0; }

IcpResult align_icp(const Points& source, const IcpTarget& target, const Rigid& initial, const IcpOptions& opt) {
  const auto t0 = std::chrono::steady_clock::now();
  check_options(opt);
  if (target.impl_->grid && opt.max_correspondence_distance > target.impl_->grid->radius())
    throw InputError("ICP: max_correspondence_distance exceeds the radius the target's lookup grid covers");
  const Cloud::Ptr src = downsampled(source, opt, "source");
  IcpResult r;
  run_passes(src, target.impl_->cloud, target.impl_->tree, target.impl_->grid, initial, opt, 0.0, r);
  if (target.impl_->grid) {
    const NearestSampleGrid& grid = *target.impl_->grid;
    judge(*src, *target.impl_->cloud, [&grid](const Vec3& q) { return grid.nearest(q); }, opt, r);
  } else {
    judge(*src, *target.impl_->cloud, TreeNearest{*target.impl_->tree}, opt, r);
  }
  r.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return r;
}

}  // namespace btr
