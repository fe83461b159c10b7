// The rigid step on rigid regions (the chest ring): ICP from several starts, and a check
// that the regions decide the pose at all. A nearly rotationally symmetric region (the
// phantom's ring, a torso seen from the front) fits itself as well rotated about its own
// axis as not: ICP then "accepts" a 180 deg flip with a perfect residual. So the accepted
// pose is probed by ICP restarted from it turned by 90, 180 and 270 deg about the region's
// normal axis; distinct poses that fit equally well are ambiguous, and the landmarks (when
// there are >= 3 pairs) decide between them, or the result says that nothing could.
#pragma once

#include <string>
#include <vector>

#include "breast_tumour_registration/registration/icp_alignment.h"

namespace btr {

struct RigidRegionOptions {
  IcpOptions icp;
  /// Two accepted poses are "equally good" when the worse inlier RMS is within
  /// rms_factor * best + rms_slack and its overlap within overlap_factor * best.
  double rms_factor = 1.5;
  double rms_slack = 1e-4;  ///< [m]
  double overlap_factor = 0.9;
  /// [m] Equally good poses that put some supine region point further apart than this are distinct.
  double distinct_distance = 0.003;
  /// The landmarks decide when the best pose's landmark RMS is below this fraction of the
  /// runner-up's (landmarks sit on deforming skin, so neither fits them exactly).
  double landmark_decision_ratio = 0.5;
};

struct RigidRegionChoice {
  IcpResult icp;                  ///< the chosen candidate (icp.accepted: some start was accepted)
  int distinct_poses = 0;         ///< distinct accepted poses that fit the regions equally well
  bool decided_by_landmarks = false;
  bool undecided = false;         ///< several such poses and nothing that tells them apart
  double landmark_rms = 0;        ///< [m] of the chosen pose, when landmarks were given
  double runner_up_landmark_rms = 0;  ///< [m] of the best other distinct pose
  std::string note;               ///< what was found (empty when one pose fits)
};

/// Aligns supine_rigid onto prone_rigid (rows are points) by ICP from each start, probes
/// the best accepted pose for symmetric alternatives and chooses between equally good
/// distinct poses with the landmark pairs (landmarks_supine -> landmarks_prone, rows
/// corresponding; empty: none). Throws InputError for empty or NaN regions.
RigidRegionChoice align_rigid_regions(const Points& supine_rigid, const Points& prone_rigid,
                                      const std::vector<Rigid>& starts, const Points& landmarks_supine,
                                      const Points& landmarks_prone, const RigidRegionOptions& opt);

/// The unit axis of least spread of the rows of P (the normal of a nearly flat region).
Vec3 least_spread_axis(const Points& P);

}  // namespace btr
