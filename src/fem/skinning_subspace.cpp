#include "breast_tumour_registration/fem/skinning_subspace.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "breast_tumour_registration/base/errors.h"

namespace btr {

std::vector<int> farthest_point_sampling(const Points& V, const std::vector<int>& seeds, int count,
                                         const std::vector<int>& candidates_in, double* covering_radius) {
  std::vector<int> candidates = candidates_in;
  if (candidates.empty()) {
    candidates.resize(V.rows());
    for (Eigen::Index i = 0; i < V.rows(); ++i) candidates[i] = static_cast<int>(i);
  }
  std::vector<int> samples = seeds;
  std::vector<double> dist(candidates.size(), std::numeric_limits<double>::infinity());
  auto relax = [&](int s) {
    for (size_t c = 0; c < candidates.size(); ++c)
      dist[c] = std::min(dist[c], (V.row(candidates[c]) - V.row(s)).squaredNorm());
  };
  for (int s : samples) relax(s);
  if (samples.empty() && !candidates.empty()) {
    samples.push_back(candidates[0]);
    relax(candidates[0]);
  }
  while (static_cast<int>(samples.size()) < count) {
    const size_t far = std::max_element(dist.begin(), dist.end()) - dist.begin();
    if (dist[far] <= 0) break;  // every candidate is a sample
    samples.push_back(candidates[far]);
    relax(candidates[far]);
  }
  if (covering_radius) *covering_radius = dist.empty() ? 0.0 : std::sqrt(*std::max_element(dist.begin(), dist.end()));
  return samples;
}

SkinningSubspace build_skinning_subspace(const Points& X, double volume, const std::vector<int>& seeds,
                                         const std::vector<bool>& fixed, const SubspaceOptions& opt) {
  if (opt.handles < 1) throw InputError("subspace needs at least one handle");
  if (!(opt.sigma > 0)) throw InputError("subspace sigma must be positive");
  if (!(volume > 0)) throw InputError("subspace needs a positive body volume");
  std::vector<int> free;
  for (Eigen::Index i = 0; i < X.rows(); ++i)
    if (fixed.empty() || !fixed[i]) free.push_back(static_cast<int>(i));
  if (free.empty()) throw InputError("subspace: every vertex is fixed");
  for (int s : seeds)
    if (s < 0 || s >= X.rows()) throw InputError("subspace seed vertex " + std::to_string(s) + " out of range");

  SkinningSubspace S;
  double cover = 0;
  S.handles = farthest_point_sampling(X, seeds, std::max<int>(opt.handles, static_cast<int>(seeds.size())), free, &cover);
  const int k = static_cast<int>(S.handles.size());
  S.radius = std::max(std::cbrt(3.0 * opt.sigma * volume / (4.0 * M_PI * k)), 1.5 * cover);
  const double r = S.radius;

  // Wendland C2 weights phi(t) = (1-t)^4 (4t+1), normalized per vertex (partition of unity).
  std::vector<Eigen::Triplet<double>> trip;
  const Vec3 centre = X.colwise().mean().transpose();
  for (Eigen::Index i = 0; i < X.rows(); ++i) {
    if (!fixed.empty() && fixed[i]) continue;
    std::vector<std::pair<int, double>> w;
    double sum = 0;
    for (int j = 0; j < k; ++j) {
      const double t = (X.row(i) - X.row(S.handles[j])).norm() / r;
      if (t >= 1) continue;
      const double phi = std::pow(1 - t, 4) * (4 * t + 1);
      w.push_back({j, phi});
      sum += phi;
    }
    // Affine coordinates relative to the body centre keep the basis well conditioned.
    const Vec3 p = X.row(i).transpose() - centre;
    const double aff[4] = {1.0, p.x() / r, p.y() / r, p.z() / r};
    for (const auto& [j, phi] : w)
      for (int a = 0; a < 4; ++a)
        for (int c = 0; c < 3; ++c) trip.emplace_back(3 * i + c, 12 * j + 3 * a + c, phi / sum * aff[a]);
  }
  S.basis.resize(3 * X.rows(), 12 * k);
  S.basis.setFromTriplets(trip.begin(), trip.end());
  return S;
}

}  // namespace btr
