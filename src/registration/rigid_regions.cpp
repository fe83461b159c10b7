#include "breast_tumour_registration/registration/rigid_regions.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include <Eigen/Eigenvalues>

#include "breast_tumour_registration/base/units.h"

namespace btr {
namespace {

double landmark_rms(const Rigid& T, const Points& supine, const Points& prone) {
  if (supine.rows() == 0) return 0;
  return std::sqrt((transform_points(T, supine) - prone).rowwise().squaredNorm().mean());
}

}  // namespace

Vec3 least_spread_axis(const Points& P) {
  const Eigen::RowVector3d c = P.colwise().mean();
  const Mat3 C = (P.rowwise() - c).transpose() * (P.rowwise() - c);
  Eigen::SelfAdjointEigenSolver<Mat3> es(C);
  return es.eigenvectors().col(0).normalized();  // eigenvalues ascending
}

RigidRegionChoice align_rigid_regions(const Points& supine_rigid, const Points& prone_rigid,
                                      const std::vector<Rigid>& starts, const Points& landmarks_supine,
                                      const Points& landmarks_prone, const RigidRegionOptions& opt) {
  RigidRegionChoice out;
  std::vector<IcpResult> accepted;
  bool have = false;
  auto consider = [&](const Rigid& start) {
    const IcpResult icp = align_icp(supine_rigid, prone_rigid, start, opt.icp);
    if (icp.accepted) accepted.push_back(icp);
    if (!have || (icp.accepted && (!out.icp.accepted || icp.inlier_rms < out.icp.inlier_rms))) {
      out.icp = icp;
      have = true;
    }
  };
  for (const Rigid& s : starts) consider(s);
  if (!out.icp.accepted) return out;

  // Probe: the best pose turned about the prone region's normal axis through its centroid.
  const Vec3 axis = least_spread_axis(prone_rigid);
  const Vec3 centre = prone_rigid.colwise().mean().transpose();
  const Rigid best = out.icp.transform;
  for (int k = 1; k <= 3; ++k) {
    Rigid turn = Rigid::Identity();
    turn.linear() = Eigen::AngleAxisd(k * M_PI / 2, axis).toRotationMatrix();
    turn.translation() = centre - turn.linear() * centre;
    consider(turn * best);
  }

  // The equally good accepted poses, grouped into distinct ones (best RMS first).
  const IcpResult& top = out.icp;
  std::vector<IcpResult> equal;
  for (const auto& c : accepted)
    if (c.inlier_rms <= opt.rms_factor * top.inlier_rms + opt.rms_slack && c.overlap >= opt.overlap_factor * top.overlap)
      equal.push_back(c);
  std::sort(equal.begin(), equal.end(), [](const IcpResult& a, const IcpResult& b) { return a.inlier_rms < b.inlier_rms; });
  std::vector<IcpResult> distinct;
  for (const auto& c : equal) {
    bool seen = false;
    for (const auto& d : distinct)
      seen = seen || max_displacement(c.transform, d.transform, supine_rigid) <= opt.distinct_distance;
    if (!seen) distinct.push_back(c);
  }
  out.distinct_poses = static_cast<int>(distinct.size());
  if (distinct.size() <= 1) return out;

  const std::string found = "the rigid regions fit " + std::to_string(distinct.size()) +
                            " distinct poses equally well (a symmetric region: ICP alone cannot tell a turned or "
                            "flipped scan)";
  if (landmarks_supine.rows() >= 3) {
    std::vector<std::pair<double, size_t>> by_lm;
    for (size_t i = 0; i < distinct.size(); ++i)
      by_lm.emplace_back(landmark_rms(distinct[i].transform, landmarks_supine, landmarks_prone), i);
    std::sort(by_lm.begin(), by_lm.end());
    out.landmark_rms = by_lm[0].first;
    out.runner_up_landmark_rms = by_lm[1].first;
    if (by_lm[0].first < opt.landmark_decision_ratio * by_lm[1].first) {
      out.icp = distinct[by_lm[0].second];
      out.decided_by_landmarks = true;
      out.note = found + "; the landmarks decided (landmark RMS " + format_mm(by_lm[0].first) + " against " +
                 format_mm(by_lm[1].first) + " for the next pose)";
      return out;
    }
    out.undecided = true;
    out.note = found + ", and the landmarks do not tell them apart either (landmark RMS " + format_mm(by_lm[0].first) +
               " against " + format_mm(by_lm[1].first) + "); kept the pose nearest the first guess";
  } else {
    out.undecided = true;
    out.note = found + " and there are no landmarks to decide; kept the pose nearest the first guess. Give >= 3 "
               "landmark pairs, or a rigid region that is not symmetric";
  }
  // Nearest the first start (the landmark fit, or the data's own frame).
  const Rigid& first = starts.empty() ? Rigid::Identity() : starts.front();
  double dmin = std::numeric_limits<double>::infinity();
  for (const auto& d : distinct) {
    const double dist = max_displacement(d.transform, first, supine_rigid);
    if (dist < dmin) {
      dmin = dist;
      out.icp = d;
    }
  }
  return out;
}

}  // namespace btr
