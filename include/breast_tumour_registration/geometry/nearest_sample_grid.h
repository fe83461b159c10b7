// A regular grid that answers "which sample is nearest to this point?" in constant time
// for points within a fixed radius of a fixed set of samples (e.g. the model's rigid
// region in depth tracking, queried for tens of thousands of cloud points per ICP
// iteration, where a kd-tree query costs microseconds). Each cell stores the sample
// nearest to its centre, so the answer is exact up to half a cell diagonal.
#pragma once

#include <vector>

#include "breast_tumour_registration/base/types.h"

namespace btr {

class NearestSampleGrid {
 public:
  /// samples: #S by 3 [m]; cell: grid spacing [m]; radius: cells farther than this from
  /// every sample answer "none" [m]. Throws InputError for no samples, non-finite
  /// samples, non-positive sizes or a grid of more than 64 million cells.
  NearestSampleGrid(const Points& samples, double cell, double radius);

  /// Index of the sample nearest to the centre of p's cell, or -1 when p lies outside
  /// the grid or farther than `radius` (measured from the cell centre) from every sample.
  int nearest(const Vec3& p) const {
    const Eigen::Array3d f = (p - origin_).array() / cell_;
    if (!(f >= 0).all() || !(f < dims_.cast<double>()).all()) return -1;  // also rejects NaN
    const Eigen::Array3i c = f.cast<int>();
    return index_[(static_cast<size_t>(c.z()) * dims_.y() + c.y()) * dims_.x() + c.x()];
  }

  double cell() const { return cell_; }
  double radius() const { return radius_; }
  long cells() const { return static_cast<long>(index_.size()); }

 private:
  Vec3 origin_;
  Eigen::Array3i dims_;
  double cell_, radius_;
  std::vector<int> index_;
};

}  // namespace btr
