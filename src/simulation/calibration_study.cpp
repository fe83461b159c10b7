#include "breast_tumour_registration/simulation/calibration_study.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iomanip>
#include <limits>
#include <ostream>
#include <random>
#include <tuple>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/strings.h"
#include "breast_tumour_registration/geometry/vertex_normals.h"
#include "breast_tumour_registration/registration/registration_engine.h"
#include "breast_tumour_registration/registration/tumour_uncertainty.h"

namespace btr {
namespace {

/// A copy of `s` with the inputs a user cannot know drawn from `src`: the supine landmarks, the
/// supine surface along its normals, the method's gravity tilted about two horizontal axes
/// (returned through `tilt`, the model's gravity rotated the same way), and the supine rigid
/// region along its normals (so that the pose ICP fits on it is as uncertain as the data make it).
Scene noisy_copy(const Scene& s, const UncertaintySources& src, std::mt19937& rng, Rigid& tilt) {
  std::normal_distribution<double> z(0.0, 1.0);
  Scene d = s;
  for (Eigen::Index l = 0; l < d.landmark_supine.rows(); ++l)
    for (int c = 0; c < 3; ++c) d.landmark_supine(l, c) += src.landmark_sd * z(rng);
  const auto standard_normal = [&] { return z(rng); };
  if (d.supine_surface && src.depth_noise > 0) displace_along_normals(*d.supine_surface, src.depth_noise, standard_normal);
  const auto [a0, a1] = gravity_tilt_axes(s.gravity);
  const double sd = src.gravity_direction_deg * M_PI / 180;
  const double t0 = sd * z(rng), t1 = sd * z(rng);
  tilt = Rigid::Identity();
  tilt.linear() = (Eigen::AngleAxisd(t1, a1) * Eigen::AngleAxisd(t0, a0)).toRotationMatrix();
  d.gravity = tilt.linear() * s.gravity;
  // The rigid region as the same camera sees it (drawn last: the other draws stay as they were).
  if (d.supine_rigid && src.depth_noise > 0 && src.rigid_pose) displace_along_normals(*d.supine_rigid, src.depth_noise, standard_normal);
  return d;
}

}  // namespace

void validate_calibration_options(const CalibrationOptions& o) {
  if (o.draws < 1) throw InputError("calibration: draws must be >= 1, got " + std::to_string(o.draws));
  if (o.samples < 2 && !(o.samples == 0 && o.linear))
    throw InputError("calibration: samples must be >= 2 (or 0 with the linearised region alone), got " + std::to_string(o.samples));
}

void run_calibration(const std::vector<Scene>& scenes, const CalibrationOptions& opt,
                     const std::function<void(const CalibrationRow&)>& sink,
                     const std::function<void(const std::string&)>& progress) {
  validate_calibration_options(opt);
  const auto say = [&](const std::string& m) {
    if (progress) progress(m);
  };
  for (const Scene& s : scenes)
    for (const auto& t : s.tumours)
      if (!t.supine_ground_truth)
        throw InputError(s.path + ": tumour '" + t.name + "' has no supine_ground_truth; calibration needs the truth");
  RegistrationOptions ro = opt.registration;
  ro.uncertainty.enabled = opt.linear;
  for (size_t si = 0; si < scenes.size(); ++si) {
    const UncertaintySources& src = scenes[si].uncertainty;  // drawn into the copies and sampled
    validate_uncertainty_sources(src);
    ro.uncertainty.sources = src;
    RegistrationEngine base(scenes[si]);
    const PreparedScene& prepared = base.prepare(ro);
    for (int k = 0; k < opt.draws; ++k) {
      // One stream per scene and copy: a copy's noise does not depend on the others.
      std::seed_seq seq{opt.seed, static_cast<unsigned>(si), static_cast<unsigned>(k)};
      std::mt19937 rng(seq);
      Rigid tilt;
      const Scene noisy = noisy_copy(prepared.scene, src, rng, tilt);
      RegistrationModel model = prepared.model;
      model.gravity = tilt.linear() * model.gravity;
      const auto t0 = std::chrono::steady_clock::now();
      RegistrationEngine engine(noisy, std::move(model), prepared.warnings);
      RegistrationResult nominal;
      SampledUncertainty su;
      try {
        nominal = engine.solve(ro);
        if (opt.samples > 0)
          su = engine.sample_uncertainty(ro, ro.uncertainty, opt.samples, opt.seed * 7919u + static_cast<unsigned>(k), nominal);
      } catch (const std::exception& e) {
        say(scenes[si].path + " draw " + std::to_string(k) + ": failed: " + e.what());
        continue;
      }
      const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
      const double nan = std::numeric_limits<double>::quiet_NaN();
      for (size_t i = 0; i < nominal.tumours.size(); ++i) {
        const TumourResult& t = nominal.tumours[i];
        CalibrationRow row;
        row.scene = scenes[si].path;
        row.tumour = t.name;
        row.draw = k;
        row.tilt_deg = Eigen::AngleAxisd(tilt.linear()).angle() * 180 / M_PI;
        row.error = t.centroid_distance;
        row.sampled_radius_95 = row.sampled_rank = row.sampled_radius_95_sources = row.sampled_rank_sources = nan;
        row.discretisation = nan;
        if (i < su.tumours.size() && !su.tumours[i].centroids.empty()) {
          const auto& st = su.tumours[i];
          std::vector<Vec3> offsets;
          for (const Vec3& c : st.centroids) offsets.push_back(c - t.centroid);
          // The truth's rank among the region's distances: with the discretisation and without.
          const auto rank = [&](const Vec3& shift) {
            const std::vector<double> d = sampled_distances(offsets, shift);
            const auto nearer = std::count_if(d.begin(), d.end(), [&](double x) { return x < row.error; });
            return static_cast<double>(nearer) / static_cast<double>(d.size());
          };
          row.sampled_radius_95 = st.radius_95;
          row.sampled_rank = rank(st.discretisation);
          row.sampled_radius_95_sources = st.radius_95_sources;
          row.sampled_rank_sources = rank(Vec3::Zero());
          if (su.discretisation_estimated) row.discretisation = st.discretisation.norm();
        }
        row.linear_radius_95 = t.uncertainty ? t.uncertainty->radius_95 : nan;
        row.linear_level = t.uncertainty ? probability_within(t.uncertainty->covariance, row.error) : nan;
        row.samples = su.samples;
        row.samples_not_converged = su.not_converged;
        row.youngs_modulus = nominal.estimated_youngs_modulus > 0 ? nominal.estimated_youngs_modulus : scenes[si].material.youngs_modulus;
        row.youngs_modulus_log_sd = nominal.estimated_youngs_modulus_log_sd;
        row.converged = nominal.converged;
        row.seconds = seconds;
        sink(row);
      }
      say(scenes[si].path + " draw " + std::to_string(k) + ": " + (nominal.converged ? "converged" : "not converged") + ", " +
          std::to_string(su.samples) + " samples (" + std::to_string(su.not_converged) + " not converged) in " +
          std::to_string(seconds) + " s" + (su.note.empty() ? "" : "; " + su.note));
    }
  }
}

void write_calibration_csv_header(std::ostream& out) {
  out << "scene,draw,tumour,tilt_deg,error_mm,sampled_radius_95_mm,sampled_rank,linear_radius_95_mm,linear_level,samples,"
         "samples_not_converged,converged,seconds,youngs_modulus_Pa,youngs_modulus_log_sd,sampled_radius_95_sources_mm,"
         "sampled_rank_sources,discretisation_mm\n";
}

void write_calibration_csv_row(std::ostream& out, const CalibrationRow& r) {
  out << csv_field(r.scene) << ',' << r.draw << ',' << csv_field(r.tumour) << ',' << std::setprecision(6) << r.tilt_deg << ',' << r.error * 1e3 << ','
      << r.sampled_radius_95 * 1e3 << ',' << r.sampled_rank << ',' << r.linear_radius_95 * 1e3 << ',' << r.linear_level << ','
      << r.samples << ',' << r.samples_not_converged << ',' << (r.converged ? 1 : 0) << ',' << std::setprecision(4) << r.seconds
      << ',' << std::setprecision(6) << r.youngs_modulus << ',' << r.youngs_modulus_log_sd << ',' << r.sampled_radius_95_sources * 1e3
      << ',' << r.sampled_rank_sources << ',' << r.discretisation * 1e3 << '\n';
}

std::pair<double, double> wilson_interval(int k, int n) {
  if (n <= 0) return {0.0, 1.0};
  const double z = 1.959964, p = static_cast<double>(k) / n, z2n = z * z / n;
  const double centre = (p + z2n / 2) / (1 + z2n);
  const double half = z * std::sqrt(p * (1 - p) / n + z2n / (4.0 * n)) / (1 + z2n);
  return {std::max(0.0, centre - half), std::min(1.0, centre + half)};
}

Coverage observed_coverage(const std::vector<CalibrationRow>& rows, double level, bool sampled) {
  Coverage c;
  c.level = level;
  int held = 0;
  for (const auto& r : rows) {
    const double v = sampled ? r.sampled_rank : r.linear_level;
    if (std::isnan(v)) continue;
    ++c.rows;
    held += v <= level;
  }
  c.observed = c.rows ? static_cast<double>(held) / c.rows : std::numeric_limits<double>::quiet_NaN();
  std::tie(c.low, c.high) = wilson_interval(held, c.rows);
  return c;
}

}  // namespace btr
