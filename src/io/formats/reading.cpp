#include "reading.h"

#include <sstream>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/strings.h"

namespace btr {
namespace mesh_format {

std::ifstream open_in(const std::string& path, bool binary) {
  std::ifstream in(path, binary ? std::ios::binary : std::ios::in);
  if (!in) throw InputError("cannot open '" + path + "': file missing or unreadable");
  return in;
}

std::ofstream open_out(const std::string& path, bool binary) {
  std::ofstream out(path, binary ? std::ios::binary : std::ios::out);
  if (!out) throw InputError("cannot write '" + path + "' (does the folder exist?)");
  out.precision(17);
  return out;
}

[[noreturn]] void fail(const std::string& path, size_t line, const std::string& what) {
  throw InputError(path + ":" + std::to_string(line) + ": " + what);
}

double parse_double(const std::string& tok, const std::string& path, size_t line) {
  const auto v = parse_number(tok);
  if (!v) fail(path, line, "cannot parse number '" + tok + "'");
  return *v;
}

long parse_long(const std::string& tok, const std::string& path, size_t line) {
  if (const auto v = parse_integer(tok)) return *v;
  // Counts and indices are ints inside: a larger value must not wrap to a valid one.
  const bool digits = !tok.empty() && tok.find_first_not_of("+-0123456789") == std::string::npos;
  fail(path, line, digits ? "integer '" + tok + "' is out of range (at most 2^31 - 1)" : "cannot parse integer '" + tok + "'");
}

TokenStream::TokenStream(const std::string& path, bool hash_comments, size_t skip_line, const char* check_first_line)
    : path_(path) {
  auto in = open_in(path);
  std::string line;
  size_t ln = 0;
  while (std::getline(in, line)) {
    ++ln;
    if (ln == 1 && check_first_line && line.rfind(check_first_line, 0) != 0)
      throw InputError(path + ":1: missing '" + check_first_line + "' header");
    if (ln == skip_line) continue;
    if (hash_comments) line = line.substr(0, line.find('#'));
    std::istringstream ss(line);
    std::string t;
    while (ss >> t) tokens_.push_back({t, ln});
  }
  last_line_ = ln;
}

Points to_points(const std::vector<Vec3>& v, double scale) {
  Points P(v.size(), 3);
  for (size_t i = 0; i < v.size(); ++i) P.row(i) = v[i].transpose() * scale;
  return P;
}

void check_indices(const std::string& path, const Eigen::MatrixXi& idx, long n, const char* what) {
  for (Eigen::Index r = 0; r < idx.rows(); ++r)
    for (Eigen::Index c = 0; c < idx.cols(); ++c)
      if (idx(r, c) < 0 || idx(r, c) >= n)
        throw InputError(path + ": " + what + " " + std::to_string(r) + " references vertex " +
                         std::to_string(idx(r, c)) + " but the file has " + std::to_string(n) + " vertices");
}

void add_polygon(std::vector<Eigen::Vector3i>& tris, const std::vector<int>& poly, const std::string& path,
                 size_t line) {
  if (poly.size() < 3) fail(path, line, "face with fewer than 3 vertices");
  for (size_t k = 1; k + 1 < poly.size(); ++k) tris.emplace_back(poly[0], poly[k], poly[k + 1]);
}

SurfaceMesh finish(const std::string& path, const std::vector<Vec3>& verts,
                   const std::vector<Eigen::Vector3i>& tris, double scale, bool require_faces) {
  SurfaceMesh m;
  m.V = to_points(verts, scale);
  m.F.resize(tris.size(), 3);
  for (size_t i = 0; i < tris.size(); ++i) m.F.row(i) = tris[i].transpose();
  if (m.F.rows() == 0 && require_faces) throw InputError(path + ": no faces");
  check_indices(path, m.F, m.V.rows(), "face");
  return m;
}


void write_vertex_and_triangle_rows(std::ostream& out, const SurfaceMesh& m, double inv) {
  for (Eigen::Index i = 0; i < m.V.rows(); ++i)
    out << m.V(i, 0) * inv << ' ' << m.V(i, 1) * inv << ' ' << m.V(i, 2) * inv << '\n';
  for (Eigen::Index i = 0; i < m.F.rows(); ++i)
    out << "3 " << m.F(i, 0) << ' ' << m.F(i, 1) << ' ' << m.F(i, 2) << '\n';
}

}  // namespace mesh_format
}  // namespace btr
