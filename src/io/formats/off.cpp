// OFF (Object File Format): counts in the header, then vertices and polygons; per-face colours are skipped.
#include "formats.h"

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/strings.h"
#include "reading.h"

namespace btr {
namespace mesh_format {

SurfaceMesh read_off(const std::string& path, double scale, bool require_faces) {
  TokenStream ts(path, true);
  if (ts.done() || lower_case(ts.peek().text).find("off") == std::string::npos) throw InputError(path + ": missing OFF header");
  ts.next("header");
  const long nv = ts.next_count("vertex count", 0);
  const long nf = ts.next_count("face count", 0);
  ts.next("edge count");
  if (static_cast<unsigned long>(nv) * 3 + static_cast<unsigned long>(nf) * 4 > ts.remaining())
    throw InputError(path + ": the header says " + std::to_string(nv) + " vertices and " + std::to_string(nf) +
                     " faces, more than the file holds");
  std::vector<Vec3> verts;
  verts.reserve(nv);
  for (long i = 0; i < nv; ++i) {
    Vec3 p;
    for (int c = 0; c < 3; ++c) p[c] = ts.next_double("vertex coordinate");
    verts.push_back(p);
  }
  std::vector<Eigen::Vector3i> tris;
  for (long i = 0; i < nf; ++i) {
    const size_t line = ts.done() ? 0 : ts.peek().line;
    const long n = ts.next_long("face size");
    std::vector<int> poly;
    for (long j = 0; j < n; ++j) poly.push_back(static_cast<int>(ts.next_long("face index")));
    add_polygon(tris, poly, path, line);
    ts.skip_rest_of_line(line);  // optional per-face colour
  }
  return finish(path, verts, tris, scale, require_faces);
}

void write_off(const std::string& path, const SurfaceMesh& m, double inv) {
  auto out = open_out(path);
  out << "OFF\n" << m.V.rows() << ' ' << m.F.rows() << " 0\n";
  write_vertex_and_triangle_rows(out, m, inv);
}

}  // namespace mesh_format
}  // namespace btr
