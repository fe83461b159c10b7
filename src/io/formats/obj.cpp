// Wavefront OBJ: "v" and "f" records, polygons fan-triangulated, negative (relative) indices.
#include "formats.h"

#include <sstream>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/strings.h"
#include "reading.h"

namespace btr {
namespace mesh_format {

SurfaceMesh read_obj(const std::string& path, double scale, bool require_faces) {
  auto in = open_in(path);
  std::vector<Vec3> verts;
  std::vector<Eigen::Vector3i> tris;
  std::string line;
  size_t ln = 0;
  while (std::getline(in, line)) {
    ++ln;
    std::istringstream ss(line);
    std::string tag;
    if (!(ss >> tag) || tag[0] == '#') continue;
    if (tag == "v") {
      std::string a, b, c;
      if (!(ss >> a >> b >> c)) fail(path, ln, "vertex needs 3 coordinates");
      verts.emplace_back(parse_double(a, path, ln), parse_double(b, path, ln), parse_double(c, path, ln));
    } else if (tag == "f") {
      std::vector<int> poly;
      std::string tok;
      while (ss >> tok) {
        const std::string head = tok.substr(0, tok.find('/'));
        long idx = parse_long(head, path, ln);
        if (idx < 0) idx = static_cast<long>(verts.size()) + idx + 1;  // OBJ relative index
        if (idx < 1) fail(path, ln, "face index " + head + " out of range");
        poly.push_back(static_cast<int>(idx - 1));
      }
      add_polygon(tris, poly, path, ln);
    }
  }
  return finish(path, verts, tris, scale, require_faces);
}

void write_obj(const std::string& path, const SurfaceMesh& m, double inv) {
  auto out = open_out(path);
  out << "# breast_tumour_registration\n";
  for (Eigen::Index i = 0; i < m.V.rows(); ++i)
    out << "v " << m.V(i, 0) * inv << ' ' << m.V(i, 1) * inv << ' ' << m.V(i, 2) * inv << '\n';
  for (Eigen::Index i = 0; i < m.F.rows(); ++i)
    out << "f " << m.F(i, 0) + 1 << ' ' << m.F(i, 1) + 1 << ' ' << m.F(i, 2) + 1 << '\n';
}

}  // namespace mesh_format
}  // namespace btr
