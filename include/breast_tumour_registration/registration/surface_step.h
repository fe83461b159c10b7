// Surface-guided deformation (thesis Sec. 4.4, Algorithm 2): the prone skin vertices (not
// the chest wall, not the interior) are projected onto the supine surface (CGAL AABB tree);
// soft point (eq. 4.2) and point-to-plane (eq. 4.3) springs hold them there while the
// interior follows; the chest wall is fixed by eliminating its DOFs, so every system is
// symmetric positive definite (the thesis solves a KKT system with LU instead). Projection
// and Newton alternate (Anderson-accelerated) until the skin is estimated to be within the
// tolerance of the alternation's fixed point.
#pragma once

#include "breast_tumour_registration/geometry/anchor.h"
#include "breast_tumour_registration/geometry/rigid_transform.h"
#include "breast_tumour_registration/geometry/surface_projector.h"
#include "breast_tumour_registration/registration/registration_model.h"
#include "breast_tumour_registration/registration/step_solvers.h"

namespace btr {

/// How the point springs hold a skin vertex along the supine surface (tangentially).
enum class SkinSliding {
  /// Thesis Algorithm 2: at every projection the point springs pull towards the latest
  /// closest point, a proximal term that vanishes at the alternation's fixed point. The skin
  /// creeps along the scan towards the point-to-plane limit; on soft tissue with a free pose
  /// it creeps at a contraction of 0.98 to 0.99 per projection and ends on the cap, and where
  /// the model's material is not the body's, that limit lay farther from the truth than the
  /// states on the way (BENCHMARKS.md, issue 10, "skin sliding").
  Free,
  /// As Free until the skin creeps: it moves less than projection_tolerance per projection
  /// (where the thesis's own criterion stops) and the alternation contracts at
  /// hold_contraction or slower. From then on each held vertex's point spring keeps, along the
  /// surface, the closest point the vertex had there, while the point-to-plane spring follows
  /// the projections. The alternation then minimises one energy (elastic + gravity + the skin
  /// on the scan, held along it where it settled) and contracts to its fixed point in a few
  /// projections. Where Free contracts quickly (stiff tissue) nothing changes. A free skin that
  /// stalls (stall_projections without a new low) is held where it is, and the alternation goes
  /// on; only a held skin that stalls is reported as a stall.
  HeldWhereSettled,
};

struct SurfaceStepOptions {
  double point_weight = 30;      ///< [N/m] per skin vertex: allows tangential sliding
  double plane_weight = 3000;    ///< [N/m] per skin vertex: holds the skin on the surface
  bool gravity = true;
  /// Safety cap on the outer iterations (projection + Newton); reaching it is reported as
  /// not converged, with the last change of the projections.
  int max_projections = 40;
  int newton_per_projection = 1; ///< Newton iterations between projections (thesis: 1)
  /// [m] Convergence: the held skin's estimated RMS distance from the fixed point of the
  /// projection/Newton alternation, |G(x) - x| / (1 - q) with q the rate at which that
  /// residual falls (fixed_point_estimate.h: the larger of its last two ratios, or two-step
  /// ratios where the residuals alternate large and small), is below this, or the alternation
  /// reached its floor (floor_projections); then Newton on the settled projections meets
  /// its gradient criterion (up to newton.max_iterations). Not the last step alone: on soft
  /// tissue q is 0.8 to 0.9, and a step of 0.1 mm left the skin about 0.5 mm from where it
  /// was going (BENCHMARKS.md, issue 10).
  double projection_tolerance = 2e-5;
  /// Anderson acceleration of the alternation (anderson_acceleration.h): the last this many
  /// differences, a proposal kept only where it lowers the energy; 0: the thesis's plain
  /// iteration. Off by default: it took 2 to 3 times fewer projections on the phantom, but on
  /// the TetGen body at 1000 Pa (pose free) it led the skin into a fold, 6.6 mm off where the
  /// plain iteration converges at 2.8 mm (BENCHMARKS.md, issue 10).
  int anderson_depth = 0;
  /// The alternation's floor: the skin's motion per projection has not reached a new low for
  /// this many projections and was at most the tolerance over them (a polyhedral
  /// surface leaves a jitter of a few hundredths of a millimetre): converged, and reported so.
  int floor_projections = 4;
  /// A stall: the skin's motion per projection has not reached a new low for this many
  /// projections (reported as not converged; with HeldWhereSettled, once the sliding is held).
  int stall_projections = 8;
  /// Projections farther than this are dropped (a partial scan, a wrong side) [m]; <= 0: keep all.
  double max_projection_distance = 0.03;
  /// With a free pose: the weight [N/m] of the point springs (landmarks) that share the pose.
  double pose_points_weight = 1e4;
  /// With a free pose: each landmark target that the supine surface holds as it holds the skin
  /// (holds_projection) is moved to its closest point there (landmarks_on_scan). Landmarks are
  /// skin markers: the scan says how deep the skin lies, the landmark where along the surface.
  /// Taken as given, a landmark's localisation noise along the normal (1.5 mm) pits its spring
  /// against the skin springs around it, and on soft tissue the skin there folded and flipped
  /// between two states at every projection: with 1.5 mm of landmark and 1 mm of depth noise,
  /// 6 of 16 registrations of SfePy's fat 1000 Pa body stalled (0 of 16 with this on, the same
  /// mean error; BENCHMARKS.md, "Landmarks on the scan").
  bool landmarks_on_scan = true;
  /// Projections onto the border of an open supine surface (the edge of a depth scan, the
  /// rim of a hole behind an occlusion) are dropped: that skin is not in the scan.
  bool reject_boundary = true;
  /// The normal of the point-to-plane springs on a supine mesh (the pipeline builds its
  /// projector with it). Interpolated by default: with the closest face's normal the springs
  /// jump where a closest point crosses an edge, and on soft tissue the alternation ended in a
  /// jitter of about 0.1 mm per projection instead of contracting (issue 10, BENCHMARKS.md:
  /// not converged 38 -> 17 of 116 suite runs on the phantom, 61 -> 48 of 112 on the TetGen
  /// body; on SfePy's truth every scene as close or closer).
  MeshNormals target_normals = MeshNormals::Interpolated;
  /// A supine mesh whose noise along its normals (estimate_surface_noise) exceeds this [m] is
  /// denoised along its normals first (denoise_surface; the pipeline does it where it builds
  /// the projector, unless the scene says `supine.denoise: off`); <= 0: never. Chosen on the
  /// phantom and SfePy's body with 0.3 to 2 mm of noise (BENCHMARKS.md, "A noisy supine mesh"):
  /// from 1 mm of noise (read as 1.04 to 1.13 mm) denoising lowered the mean tumour error on
  /// both and took fewer projections; at 0.5 mm (read as 0.52 to 0.60 mm) it cost the phantom
  /// 0.01 to 0.03 mm. No noise-free scan of our bodies reads above 0.58 mm, so none is touched.
  /// Depth-camera scans are left to the live path's own smoothing in their image grid.
  double scan_denoising_min_noise = 8e-4;
  /// Where the steps read a freely sliding skin as settled (the estimate or the floor), check it
  /// by another route: one Newton step on the energy without the point springs (their proximal
  /// pull vanishes at the free limit) says how far that limit lies. Beyond the tolerance the skin
  /// is not settled, and with HeldWhereSettled its sliding is held there (a creep the steps did
  /// not see). The steps' rate is read from the last few steps, and a slow slide under a faster
  /// mode escapes it: on the 12 mm ring-free phantom at 600 Pa, unloaded (pose free), the balanced
  /// preset stopped "0.081 mm from the fixed point" with the skin 0.162 mm RMS from it (this
  /// check reads 0.141 mm there; BENCHMARKS.md, issue 10, 2026-12-07). Costs one Newton
  /// iteration per check.
  bool verify_free_limit = true;
  /// Chosen on two bodies and the independent truth (BENCHMARKS.md, "skin sliding").
  SkinSliding sliding = SkinSliding::HeldWhereSettled;
  /// HeldWhereSettled: the contraction per projection from which a settled skin's sliding is a
  /// creep, and is held.
  double hold_contraction = 0.95;
  /// Newton's inversion_stall_alpha in this step: a step the no-new-inversion rule cut to this
  /// fraction or less lets the line search invert for the rest of the step (soft tissue under
  /// the skin springs otherwise crawls far from equilibrium with ever shorter steps, and the
  /// small change per projection passes for a settled skin: BENCHMARKS.md, "Inverted elements
  /// at the limit"). A limit that then folds beyond Newton's allowance is not converged.
  /// 1/8 was chosen on two bodies (1/128, 1/32, 1/8, 1/2, 1 measured; from 1/8 up the same
  /// not-converged counts and errors, 1/8 with the fewest runs made worse).
  double inversion_stall_alpha = 1.0 / 8;
  NewtonOptions newton;
};

/// Whether the surface step holds a skin vertex by this projection: within
/// max_projection_distance (when > 0) and, with reject_boundary, not on the surface's border.
bool holds_projection(const Projection& c, const SurfaceStepOptions& opt);

/// supine: projection onto the supine surface in the model frame (a mesh, closed or open,
/// or a point cloud). x: current positions, updated in place.
/// pose == nullptr: the surface stays where it is. Otherwise it may move rigidly and its pose
/// is solved jointly with the deformation (RigidFreeSurfaceEnergy); on return *pose maps the
/// model frame into the frame the projector was given in.
/// pose_points (with a free pose only): point correspondences such as the landmarks, targets
/// in the projector's frame, that share the pose (opt.pose_points_weight).
/// cache: an engine's solvers for this model (the Hessian pattern and its symbolic analysis
/// are reused while unchanged); nullptr builds them for this call.
struct PosePoints {
  std::vector<Anchor> anchors;
  Points targets;
};

/// Landmark targets as the pose-free surface step takes them (SurfaceStepOptions::
/// landmarks_on_scan): a target whose projection onto `supine` holds_projection is replaced by
/// that closest point, with the surface's unit normal there; any other target is kept as given,
/// with a zero normal. Targets and surface in one frame. To first order a moved target follows
/// its landmark along the surface only, and the surface's own depth noise along the normal: what
/// the linearised uncertainty takes (FreePoseLinearisation::landmark_normals).
struct LandmarksOnScan {
  Points targets;   ///< one row per target
  Points normals;   ///< the surface's unit normal at the moved target; zero: kept as given
  int moved = 0;    ///< how many targets were moved onto the surface
};
LandmarksOnScan landmarks_on_scan(const SurfaceProjector& supine, const Points& targets, const SurfaceStepOptions& opt);
StepReport surface_step(const RegistrationModel& model, const SurfaceProjector& supine, const SurfaceStepOptions& opt,
                        Points& x, const StepCallback& callback = {}, Rigid* pose = nullptr,
                        const PosePoints* pose_points = nullptr, StepSolvers* cache = nullptr);

}  // namespace btr
