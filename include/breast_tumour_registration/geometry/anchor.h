// A point carried by mesh vertices (a landmark on the skin, a point inside an element):
// the barycentric reference that the landmark energies, the scene and the attachment share.
#pragma once

#include "breast_tumour_registration/base/types.h"

namespace btr {

/// A point carried by up to four mesh vertices: p(x) = sum_k w_k x_{v_k}
/// (a vertex, a barycentric point on a boundary triangle, or one inside a tetrahedron).
struct Anchor {
  int count = 1;
  int v[4] = {0, 0, 0, 0};
  double w[4] = {1, 0, 0, 0};

  static Anchor vertex(int i) {
    Anchor a;
    a.v[0] = i;
    return a;
  }
  Vec3 position(const Points& x) const {
    Vec3 p = Vec3::Zero();
    for (int k = 0; k < count; ++k) p += w[k] * x.row(v[k]).transpose();
    return p;
  }
};

}  // namespace btr
