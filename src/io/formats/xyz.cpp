// Point clouds as text: x y z per line, '#' starts a comment.
#include "formats.h"

#include "reading.h"

namespace btr {
namespace mesh_format {

Points read_xyz(const std::string& path, double scale) {
  TokenStream ts(path, true);
  std::vector<Vec3> v;
  while (!ts.done()) {
    Vec3 p;
    for (int c = 0; c < 3; ++c) p[c] = ts.next_double("coordinate");
    v.push_back(p);
  }
  return to_points(v, scale);
}

}  // namespace mesh_format
}  // namespace btr
