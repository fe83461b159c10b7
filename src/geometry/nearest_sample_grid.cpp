#include "breast_tumour_registration/geometry/nearest_sample_grid.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "breast_tumour_registration/base/errors.h"

namespace btr {

NearestSampleGrid::NearestSampleGrid(const Points& samples, double cell, double radius) : cell_(cell), radius_(radius) {
  if (samples.rows() == 0) throw InputError("nearest-sample grid: no samples");
  if (!samples.allFinite()) throw InputError("nearest-sample grid: samples must be finite");
  if (!(cell > 0) || !(radius > 0)) throw InputError("nearest-sample grid: cell and radius must be positive");
  const Vec3 lo = samples.colwise().minCoeff().transpose(), hi = samples.colwise().maxCoeff().transpose();
  origin_ = lo - Vec3::Constant(radius);
  const Eigen::Array3d extent = (hi - lo).array() + 2 * radius;
  const Eigen::Array3d n = (extent / cell).ceil() + 1;
  if (n.prod() > 64e6)
    throw InputError("nearest-sample grid: " + std::to_string(static_cast<long long>(n.prod())) +
                     " cells; use a larger cell or a smaller radius");
  dims_ = n.cast<int>();
  index_.assign(static_cast<size_t>(dims_.prod()), -1);
  std::vector<float> best(index_.size(), std::numeric_limits<float>::infinity());
  // Every sample claims the cells within `radius` whose centre it is nearest to.
  const int reach = static_cast<int>(std::ceil(radius / cell));
  const double r2 = radius * radius;
  for (Eigen::Index s = 0; s < samples.rows(); ++s) {
    const Vec3 p = samples.row(s).transpose();
    const Eigen::Array3i c = ((p - origin_).array() / cell).floor().cast<int>();
    for (int z = std::max(0, c.z() - reach); z <= std::min(dims_.z() - 1, c.z() + reach); ++z)
      for (int y = std::max(0, c.y() - reach); y <= std::min(dims_.y() - 1, c.y() + reach); ++y)
        for (int x = std::max(0, c.x() - reach); x <= std::min(dims_.x() - 1, c.x() + reach); ++x) {
          const Vec3 centre = origin_ + cell * (Vec3(x, y, z) + Vec3::Constant(0.5));
          const double d2 = (centre - p).squaredNorm();
          if (d2 > r2) continue;
          const size_t k = (static_cast<size_t>(z) * dims_.y() + y) * dims_.x() + x;
          if (d2 < best[k]) {
            best[k] = static_cast<float>(d2);
            index_[k] = static_cast<int>(s);
          }
        }
  }
}

}  // namespace btr
