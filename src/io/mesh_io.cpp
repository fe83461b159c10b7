#include "breast_tumour_registration/io/mesh_io.h"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <map>
#include <limits>
#include <sstream>
#include <vector>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/strings.h"

namespace btr {
namespace {

std::ifstream open_in(const std::string& path, bool binary = false) {
  std::ifstream in(path, binary ? std::ios::binary : std::ios::in);
  if (!in) throw InputError("cannot open '" + path + "': file missing or unreadable");
  return in;
}

std::ofstream open_out(const std::string& path, bool binary = false) {
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

// The whitespace-separated tokens of a text file with their line numbers, for the formats
// whose records span lines (OFF, legacy VTK, Medit).
class TokenStream {
 public:
  struct Token {
    std::string text;
    size_t line;
  };
  /// hash_comments: '#' starts a comment; skip_line (1-based, 0: none) is ignored entirely;
  /// check_first_line, when given, must start line 1.
  TokenStream(const std::string& path, bool hash_comments, size_t skip_line = 0, const char* check_first_line = nullptr)
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
  bool done() const { return pos_ >= tokens_.size(); }
  size_t remaining() const { return tokens_.size() - pos_; }
  const Token& peek() const { return tokens_[pos_]; }
  const Token& next(const char* what) {
    if (done()) fail(path_, last_line_, std::string("unexpected end of file, expected ") + what);
    return tokens_[pos_++];
  }
  long next_long(const char* what) {
    const Token& t = next(what);
    return parse_long(t.text, path_, t.line);
  }
  double next_double(const char* what) {
    const Token& t = next(what);
    return parse_double(t.text, path_, t.line);
  }
  /// A count from a header, checked against what the file holds before anything is allocated:
  /// each item needs at least tokens_per_item more values.
  long next_count(const char* what, long tokens_per_item) {
    const Token& t = next(what);
    const long n = parse_long(t.text, path_, t.line);
    if (n < 0) fail(path_, t.line, std::string(what) + " " + t.text + " is negative");
    const size_t left = tokens_.size() - pos_;
    if (static_cast<unsigned long>(n) * static_cast<unsigned long>(tokens_per_item) > left)
      fail(path_, t.line, std::string(what) + " " + t.text + " needs at least " +
                              std::to_string(static_cast<unsigned long>(n) * tokens_per_item) + " values, the file holds " +
                              std::to_string(left) + " more");
    return n;
  }
  /// Skips the remaining tokens of `line`.
  void skip_rest_of_line(size_t line) {
    while (!done() && tokens_[pos_].line == line) ++pos_;
  }

 private:
  std::string path_;
  std::vector<Token> tokens_;
  size_t pos_ = 0, last_line_ = 0;
};

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

// require_faces is false only for point clouds read from mesh formats.
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

// ---------------------------------------------------------------- OBJ
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

// ---------------------------------------------------------------- OFF
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
  for (Eigen::Index i = 0; i < m.V.rows(); ++i)
    out << m.V(i, 0) * inv << ' ' << m.V(i, 1) * inv << ' ' << m.V(i, 2) * inv << '\n';
  for (Eigen::Index i = 0; i < m.F.rows(); ++i)
    out << "3 " << m.F(i, 0) << ' ' << m.F(i, 1) << ' ' << m.F(i, 2) << '\n';
}

// ---------------------------------------------------------------- STL
// STL stores every triangle's corners; identical corners are merged into one vertex.
struct VertexMerger {
  std::map<std::array<double, 3>, int> index;
  std::vector<Vec3> verts;
  int add(const Vec3& p) {
    auto [it, inserted] = index.emplace(std::array<double, 3>{p.x(), p.y(), p.z()}, static_cast<int>(verts.size()));
    if (inserted) verts.push_back(p);
    return it->second;
  }
};

SurfaceMesh read_stl(const std::string& path, double scale, bool require_faces) {
  auto in = open_in(path, true);
  std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  if (content.size() < 15) throw InputError(path + ": file too short to be STL");
  VertexMerger merge;
  std::vector<Eigen::Vector3i> tris;
  bool binary = true;
  if (content.compare(0, 5, "solid") == 0) {
    // "solid" may also start a binary header; binary size must then match exactly.
    if (content.size() >= 84) {
      uint32_t n = 0;
      std::memcpy(&n, content.data() + 80, 4);
      binary = (84 + 50ull * n == content.size());
    } else {
      binary = false;
    }
  }
  if (binary) {
    if (content.size() < 84) throw InputError(path + ": truncated binary STL header");
    uint32_t n = 0;
    std::memcpy(&n, content.data() + 80, 4);
    if (84 + 50ull * n != content.size())
      throw InputError(path + ": binary STL says " + std::to_string(n) + " triangles but the file size does not match");
    for (uint32_t t = 0; t < n; ++t) {
      const char* rec = content.data() + 84 + 50ull * t;
      Eigen::Vector3i tri;
      for (int c = 0; c < 3; ++c) {
        float f[3];
        std::memcpy(f, rec + 12 + 12 * c, 12);
        tri[c] = merge.add(Vec3(f[0], f[1], f[2]));
      }
      tris.push_back(tri);
    }
  } else {
    std::istringstream ss(content);
    std::string line;
    size_t ln = 0;
    std::vector<int> corners;
    while (std::getline(ss, line)) {
      ++ln;
      std::istringstream ls(line);
      std::string tag;
      if (!(ls >> tag)) continue;
      tag = lower_case(tag);
      if (tag == "vertex") {
        std::string a, b, c;
        if (!(ls >> a >> b >> c)) fail(path, ln, "vertex needs 3 coordinates");
        corners.push_back(merge.add(Vec3(parse_double(a, path, ln), parse_double(b, path, ln),
                                         parse_double(c, path, ln))));
      } else if (tag == "endloop") {
        if (corners.size() != 3) fail(path, ln, "facet with " + std::to_string(corners.size()) + " vertices");
        tris.emplace_back(corners[0], corners[1], corners[2]);
        corners.clear();
      }
    }
  }
  return finish(path, merge.verts, tris, scale, require_faces);
}

void write_stl(const std::string& path, const SurfaceMesh& m, double inv) {
  auto out = open_out(path, true);
  char header[80] = {0};
  std::snprintf(header, sizeof(header), "breast_tumour_registration binary STL");
  out.write(header, 80);
  const uint32_t n = static_cast<uint32_t>(m.F.rows());
  out.write(reinterpret_cast<const char*>(&n), 4);
  for (Eigen::Index i = 0; i < m.F.rows(); ++i) {
    const Vec3 a = m.V.row(m.F(i, 0)), b = m.V.row(m.F(i, 1)), c = m.V.row(m.F(i, 2));
    Vec3 nrm = (b - a).cross(c - a);
    if (nrm.norm() > 0) nrm.normalize();
    float rec[12];
    for (int k = 0; k < 3; ++k) rec[k] = static_cast<float>(nrm[k]);
    for (int v = 0; v < 3; ++v)
      for (int k = 0; k < 3; ++k) rec[3 + 3 * v + k] = static_cast<float>(m.V(m.F(i, v), k) * inv);
    out.write(reinterpret_cast<const char*>(rec), 48);
    const uint16_t attr = 0;
    out.write(reinterpret_cast<const char*>(&attr), 2);
  }
}

// ---------------------------------------------------------------- PLY
struct PlyProperty {
  std::string type;       // scalar type, or list value type
  std::string count_type; // list count type; empty for scalars
  std::string name;
};
struct PlyElement {
  std::string name;
  long count = 0;
  std::vector<PlyProperty> props;
};

size_t ply_type_size(const std::string& t) {
  if (t == "char" || t == "int8" || t == "uchar" || t == "uint8") return 1;
  if (t == "short" || t == "int16" || t == "ushort" || t == "uint16") return 2;
  if (t == "int" || t == "int32" || t == "uint" || t == "uint32" || t == "float" || t == "float32") return 4;
  if (t == "double" || t == "float64") return 8;
  return 0;
}

double ply_read_binary(const char*& p, const char* end, const std::string& t, const std::string& path) {
  const size_t sz = ply_type_size(t);
  if (sz == 0) throw InputError(path + ": unknown PLY type '" + t + "'");
  if (p + sz > end) throw InputError(path + ": binary PLY truncated");
  double v = 0;
  if (t == "char" || t == "int8") { int8_t x; std::memcpy(&x, p, 1); v = x; }
  else if (t == "uchar" || t == "uint8") { uint8_t x; std::memcpy(&x, p, 1); v = x; }
  else if (t == "short" || t == "int16") { int16_t x; std::memcpy(&x, p, 2); v = x; }
  else if (t == "ushort" || t == "uint16") { uint16_t x; std::memcpy(&x, p, 2); v = x; }
  else if (t == "int" || t == "int32") { int32_t x; std::memcpy(&x, p, 4); v = x; }
  else if (t == "uint" || t == "uint32") { uint32_t x; std::memcpy(&x, p, 4); v = x; }
  else if (t == "float" || t == "float32") { float x; std::memcpy(&x, p, 4); v = x; }
  else { double x; std::memcpy(&x, p, 8); v = x; }
  p += sz;
  return v;
}

SurfaceMesh read_ply(const std::string& path, double scale, bool require_faces) {
  auto in = open_in(path, true);
  std::string content((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  const size_t hdr_end = content.find("end_header");
  if (content.compare(0, 3, "ply") != 0 || hdr_end == std::string::npos)
    throw InputError(path + ": not a PLY file (missing 'ply' or 'end_header')");
  std::istringstream hs(content.substr(0, hdr_end));
  std::string line, format;
  std::vector<PlyElement> elems;
  while (std::getline(hs, line)) {
    std::istringstream ls(line);
    std::string tag;
    ls >> tag;
    if (tag == "format") ls >> format;
    else if (tag == "element") {
      PlyElement e;
      if (!(ls >> e.name >> e.count) || e.count < 0 || e.count > static_cast<long>(content.size()))
        throw InputError(path + ": PLY element '" + e.name + "' has a bad count (negative, or more than the file can hold)");
      elems.push_back(e);
    }
    else if (tag == "property") {
      if (elems.empty()) throw InputError(path + ": PLY property before any element");
      PlyProperty pr;
      std::string t;
      ls >> t;
      if (t == "list") ls >> pr.count_type >> pr.type >> pr.name;
      else { pr.type = t; ls >> pr.name; }
      elems.back().props.push_back(pr);
    }
  }
  size_t body = content.find('\n', hdr_end);
  if (body == std::string::npos) throw InputError(path + ": PLY has no data after header");
  ++body;
  if (format != "ascii" && format != "binary_little_endian")
    throw InputError(path + ": PLY format '" + format + "' not supported (ascii or binary_little_endian)");
  const bool ascii = format == "ascii";
  std::istringstream as(ascii ? content.substr(body) : std::string());
  const char* p = content.data() + body;
  const char* end = content.data() + content.size();
  auto read_value = [&](const std::string& t) -> double {
    if (!ascii) return ply_read_binary(p, end, t, path);
    std::string tok;
    if (!(as >> tok)) throw InputError(path + ": PLY data ends early");
    return parse_double(tok, path, 0);
  };
  std::vector<Vec3> verts;
  std::vector<Eigen::Vector3i> tris;
  for (const auto& e : elems) {
    for (long i = 0; i < e.count; ++i) {
      Vec3 v = Vec3::Zero();
      std::vector<int> poly;
      for (const auto& pr : e.props) {
        if (!pr.count_type.empty()) {
          const double n = read_value(pr.count_type);
          if (!(n >= 0 && n <= 1e6)) throw InputError(path + ": PLY list count " + std::to_string(n) + " out of range");
          std::vector<int> vals;
          for (long j = 0; j < static_cast<long>(n); ++j) {
            const double x = read_value(pr.type);
            if (!(x >= 0 && x <= std::numeric_limits<int>::max()) || x != std::floor(x))
              throw InputError(path + ": PLY index " + std::to_string(x) + " is not an index (0 to 2^31 - 1)");
            vals.push_back(static_cast<int>(x));
          }
          if (e.name == "face" && (pr.name == "vertex_indices" || pr.name == "vertex_index")) poly = vals;
        } else {
          const double x = read_value(pr.type);
          if (e.name == "vertex") {
            if (pr.name == "x") v.x() = x;
            else if (pr.name == "y") v.y() = x;
            else if (pr.name == "z") v.z() = x;
          }
        }
      }
      if (e.name == "vertex") verts.push_back(v);
      if (e.name == "face") add_polygon(tris, poly, path, 0);
    }
  }
  return finish(path, verts, tris, scale, require_faces);
}

void write_ply(const std::string& path, const SurfaceMesh& m, double inv) {
  auto out = open_out(path);
  out << "ply\nformat ascii 1.0\ncomment breast_tumour_registration\nelement vertex " << m.V.rows()
      << "\nproperty double x\nproperty double y\nproperty double z\nelement face " << m.F.rows()
      << "\nproperty list uchar int vertex_indices\nend_header\n";
  for (Eigen::Index i = 0; i < m.V.rows(); ++i)
    out << m.V(i, 0) * inv << ' ' << m.V(i, 1) * inv << ' ' << m.V(i, 2) * inv << '\n';
  for (Eigen::Index i = 0; i < m.F.rows(); ++i)
    out << "3 " << m.F(i, 0) << ' ' << m.F(i, 1) << ' ' << m.F(i, 2) << '\n';
}

// ---------------------------------------------------------------- VTK (legacy)
// Reads one dataset attribute section (POINT_DATA or CELL_DATA with `count` items): the
// one-component SCALARS and FIELD arrays are kept in `arrays` (when given), the rest skipped.
void read_vtk_attributes(TokenStream& ts, const std::string& path, long count, std::map<std::string, std::vector<double>>* arrays) {
  auto values = [&](long n, std::vector<double>* out) {
    if (static_cast<unsigned long>(n) > ts.remaining())
      fail(path, ts.done() ? 0 : ts.peek().line, "attribute needs " + std::to_string(n) + " values, the file holds " + std::to_string(ts.remaining()));
    for (long i = 0; i < n; ++i) {
      const double v = ts.next_double("attribute value");
      if (out) out->push_back(v);
    }
  };
  while (!ts.done()) {
    const std::string kw = lower_case(ts.peek().text);
    if (kw == "point_data" || kw == "cell_data") return;
    const auto tok = ts.next("attribute");
    if (kw == "scalars") {
      const std::string name = ts.next("scalars name").text;
      ts.next("scalars type");
      long comps = 1;
      if (!ts.done() && ts.peek().line == tok.line) comps = ts.next_long("scalars components");
      if (comps < 1 || comps > 4) fail(path, tok.line, "SCALARS '" + name + "' has " + std::to_string(comps) + " components (1 to 4)");
      if (!ts.done() && lower_case(ts.peek().text) == "lookup_table") {
        ts.next("lookup_table");
        ts.next("lookup table name");
      }
      std::vector<double> v;
      values(count * comps, comps == 1 && arrays ? &v : nullptr);
      if (comps == 1 && arrays) (*arrays)[name] = std::move(v);
    } else if (kw == "field") {
      ts.next("field name");
      const long k = ts.next_long("field array count");
      for (long a = 0; a < k; ++a) {
        const auto name = ts.next("field array name");
        const long comps = ts.next_long("field array components");
        const long tuples = ts.next_long("field array tuples");
        ts.next("field array type");
        if (comps < 1 || tuples != count)
          fail(path, name.line, "FIELD array '" + name.text + "' has " + std::to_string(tuples) + " tuples of " +
                                    std::to_string(comps) + " for " + std::to_string(count) + " items");
        std::vector<double> v;
        values(comps * tuples, comps == 1 && arrays ? &v : nullptr);
        if (comps == 1 && arrays) (*arrays)[name.text] = std::move(v);
      }
    } else if (kw == "lookup_table") {
      ts.next("lookup table name");
      values(4 * ts.next_long("lookup table size"), nullptr);
    } else if (kw == "vectors" || kw == "normals") {
      ts.next("name");
      ts.next("type");
      values(3 * count, nullptr);
    } else if (kw == "tensors") {
      ts.next("name");
      ts.next("type");
      values(9 * count, nullptr);
    } else if (kw == "color_scalars") {
      ts.next("name");
      values(count * ts.next_long("color components"), nullptr);
    } else if (kw == "texture_coordinates") {
      ts.next("name");
      const long dim = ts.next_long("texture dimension");
      ts.next("type");
      values(dim * count, nullptr);
    } else {
      fail(path, tok.line, "unknown legacy VTK attribute '" + tok.text + "'");
    }
  }
}

TetMeshFile read_vtk(const std::string& path, double scale) {
  // Line 1 is the "# vtk DataFile" header, line 2 a free-form title.
  TokenStream ts(path, false, 2, "# vtk");
  ts.next("header");
  while (!ts.done() && ts.peek().line == 1) ts.next("header");
  std::vector<Vec3> verts;
  std::vector<std::vector<int>> cells;
  std::vector<int> types;
  std::map<std::string, std::vector<double>> cell_arrays;
  bool have_points = false, have_cells = false;
  while (!ts.done()) {
    const auto tok = ts.next("keyword");
    const std::string kw = lower_case(tok.text);
    if (kw == "ascii") {
    } else if (kw == "dataset") {
      const auto t = ts.next("dataset type");
      if (lower_case(t.text) != "unstructured_grid") fail(path, t.line, "dataset '" + t.text + "' is not UNSTRUCTURED_GRID");
    } else if (kw == "binary") {
      fail(path, tok.line, "binary legacy VTK is not supported; save as ASCII");
    } else if (kw == "points") {
      const long n = ts.next_count("point count", 3);
      ts.next("point type");
      verts.resize(n);
      for (long i = 0; i < n; ++i)
        for (int c = 0; c < 3; ++c) verts[i][c] = ts.next_double("coordinate");
      have_points = true;
    } else if (kw == "cells") {
      const long n = ts.next_count("cell count", 2);
      ts.next("cell list size");
      cells.resize(n);
      for (long i = 0; i < n; ++i) {
        const long m = ts.next_long("cell size");
        for (long j = 0; j < m; ++j) cells[i].push_back(static_cast<int>(ts.next_long("cell index")));
      }
      have_cells = true;
    } else if (kw == "cell_types") {
      const long n = ts.next_count("cell type count", 1);
      for (long i = 0; i < n; ++i) types.push_back(static_cast<int>(ts.next_long("cell type")));
    } else if (kw == "point_data" || kw == "cell_data") {
      const long n = ts.next_count(kw == "cell_data" ? "CELL_DATA count" : "POINT_DATA count", 0);
      const long expected = kw == "cell_data" ? static_cast<long>(cells.size()) : static_cast<long>(verts.size());
      if (n != expected)
        fail(path, tok.line, tok.text + " " + std::to_string(n) + " does not match the " + std::to_string(expected) +
                                 (kw == "cell_data" ? " cells" : " points"));
      read_vtk_attributes(ts, path, n, kw == "cell_data" ? &cell_arrays : nullptr);
    }
  }
  if (!have_points || !have_cells) throw InputError(path + ": missing POINTS or CELLS section");
  if (!types.empty() && types.size() != cells.size())
    throw InputError(path + ": CELL_TYPES count differs from CELLS count");
  TetMeshFile f;
  f.mesh.V = to_points(verts, scale);
  std::vector<Eigen::Vector4i> tets;
  std::vector<size_t> tet_cell;  // VTK cell of each tetrahedron (for the cell data)
  for (size_t i = 0; i < cells.size(); ++i) {
    const int type = types.empty() ? (cells[i].size() == 4 ? 10 : -1) : types[i];
    if (type == 1 || type == 3 || type == 5) continue;  // vertices, lines, triangles (e.g. boundary) are skipped
    if (type != 10 || cells[i].size() != 4)
      throw InputError(path + ": cell " + std::to_string(i) + " has VTK type " + std::to_string(type) +
                       " (only tetrahedra, type 10, are supported)");
    tets.emplace_back(cells[i][0], cells[i][1], cells[i][2], cells[i][3]);
    tet_cell.push_back(i);
  }
  f.mesh.T.resize(tets.size(), 4);
  for (size_t i = 0; i < tets.size(); ++i) f.mesh.T.row(i) = tets[i].transpose();
  if (f.mesh.T.rows() == 0) throw InputError(path + ": no tetrahedra");
  check_indices(path, f.mesh.T, f.mesh.V.rows(), "tetrahedron");
  for (auto& [name, v] : cell_arrays) {
    std::vector<double> per_tet(tet_cell.size());
    for (size_t i = 0; i < tet_cell.size(); ++i) per_tet[i] = v[tet_cell[i]];
    f.cell_arrays[name] = std::move(per_tet);
  }
  return f;
}

void write_vtk(const std::string& path, const TetMesh& m, double inv, const std::vector<int>& labels, const std::string& title) {
  auto out = open_out(path);
  out << "# vtk DataFile Version 3.0\n" << (title.empty() ? "breast_tumour_registration tetrahedral mesh" : title)
      << "\nASCII\nDATASET UNSTRUCTURED_GRID\n";
  out << "POINTS " << m.V.rows() << " double\n";
  for (Eigen::Index i = 0; i < m.V.rows(); ++i)
    out << m.V(i, 0) * inv << ' ' << m.V(i, 1) * inv << ' ' << m.V(i, 2) * inv << '\n';
  out << "CELLS " << m.T.rows() << ' ' << 5 * m.T.rows() << '\n';
  for (Eigen::Index i = 0; i < m.T.rows(); ++i)
    out << "4 " << m.T(i, 0) << ' ' << m.T(i, 1) << ' ' << m.T(i, 2) << ' ' << m.T(i, 3) << '\n';
  out << "CELL_TYPES " << m.T.rows() << '\n';
  for (Eigen::Index i = 0; i < m.T.rows(); ++i) out << "10\n";
  if (labels.empty()) return;
  out << "CELL_DATA " << m.T.rows() << "\nSCALARS label int 1\nLOOKUP_TABLE default\n";
  for (int l : labels) out << l << '\n';
}

// ---------------------------------------------------------------- Medit
TetMeshFile read_medit(const std::string& path, double scale) {
  TokenStream ts(path, true);
  auto skip_block = [&](int per_item) {
    const long n = ts.next_long("count");
    for (long i = 0; i < n * per_item; ++i) ts.next("value");
  };
  std::vector<Vec3> verts;
  std::vector<Eigen::Vector4i> tets;
  std::vector<double> refs;
  bool have_v = false;
  while (!ts.done()) {
    const auto tok = ts.next("keyword");
    const std::string kw = lower_case(tok.text);
    if (kw == "meshversionformatted" || kw == "dimension") {
      const auto t = ts.next("value");
      if (kw == "dimension" && t.text != "3") fail(path, t.line, "only Dimension 3 is supported");
    } else if (kw == "vertices") {
      const long n = ts.next_count("vertex count", 4);
      verts.resize(n);
      for (long i = 0; i < n; ++i) {
        for (int c = 0; c < 3; ++c) verts[i][c] = ts.next_double("coordinate");
        ts.next("vertex reference");
      }
      have_v = true;
    } else if (kw == "tetrahedra") {
      const long n = ts.next_count("tetrahedron count", 5);
      for (long i = 0; i < n; ++i) {
        Eigen::Vector4i t;
        for (int c = 0; c < 4; ++c) t[c] = static_cast<int>(ts.next_long("tetrahedron index")) - 1;  // 1-based
        refs.push_back(static_cast<double>(ts.next_long("tetrahedron reference")));
        tets.push_back(t);
      }
    } else if (kw == "triangles") {
      skip_block(4);
    } else if (kw == "edges") {
      skip_block(3);
    } else if (kw == "corners" || kw == "requiredvertices" || kw == "ridges" || kw == "requirededges") {
      skip_block(1);
    } else if (kw == "end") {
      break;
    } else {
      fail(path, tok.line, "unknown Medit keyword '" + tok.text + "'");
    }
  }
  if (!have_v || tets.empty()) throw InputError(path + ": missing Vertices or Tetrahedra section");
  TetMeshFile f;
  f.mesh.V = to_points(verts, scale);
  f.mesh.T.resize(tets.size(), 4);
  for (size_t i = 0; i < tets.size(); ++i) f.mesh.T.row(i) = tets[i].transpose();
  check_indices(path, f.mesh.T, f.mesh.V.rows(), "tetrahedron");
  f.cell_arrays["ref"] = std::move(refs);
  return f;
}

void write_medit(const std::string& path, const TetMesh& m, double inv, const std::vector<int>& labels) {
  auto out = open_out(path);
  out << "MeshVersionFormatted 2\nDimension 3\nVertices\n" << m.V.rows() << '\n';
  for (Eigen::Index i = 0; i < m.V.rows(); ++i)
    out << m.V(i, 0) * inv << ' ' << m.V(i, 1) * inv << ' ' << m.V(i, 2) * inv << " 0\n";
  out << "Tetrahedra\n" << m.T.rows() << '\n';
  for (Eigen::Index i = 0; i < m.T.rows(); ++i)
    out << m.T(i, 0) + 1 << ' ' << m.T(i, 1) + 1 << ' ' << m.T(i, 2) + 1 << ' ' << m.T(i, 3) + 1 << ' '
        << (labels.empty() ? 1 : labels[i]) << '\n';
  out << "End\n";
}

}  // namespace

std::string file_extension(const std::string& path) {
  const size_t dot = path.find_last_of('.');
  const size_t slash = path.find_last_of('/');
  if (dot == std::string::npos || (slash != std::string::npos && dot < slash)) return "";
  return lower_case(path.substr(dot));
}

SurfaceMesh read_surface(const std::string& path, LengthUnit unit) {
  const std::string ext = file_extension(path);
  const double s = metres_per_unit(unit);
  if (ext == ".obj") return read_obj(path, s, true);
  if (ext == ".off") return read_off(path, s, true);
  if (ext == ".stl") return read_stl(path, s, true);
  if (ext == ".ply") return read_ply(path, s, true);
  throw InputError("'" + path + "': unknown surface format '" + ext + "' (expected .obj, .ply, .stl or .off)");
}

void write_surface(const std::string& path, const SurfaceMesh& mesh, LengthUnit unit) {
  const std::string ext = file_extension(path);
  const double inv = 1.0 / metres_per_unit(unit);
  if (ext == ".obj") return write_obj(path, mesh, inv);
  if (ext == ".off") return write_off(path, mesh, inv);
  if (ext == ".stl") return write_stl(path, mesh, inv);
  if (ext == ".ply") return write_ply(path, mesh, inv);
  throw InputError("'" + path + "': unknown surface format '" + ext + "' (expected .obj, .ply, .stl or .off)");
}

Points read_point_cloud(const std::string& path, LengthUnit unit) {
  const std::string ext = file_extension(path);
  Points P;
  if (ext == ".xyz" || ext == ".txt") {
    TokenStream ts(path, true);
    std::vector<Vec3> v;
    while (!ts.done()) {
      Vec3 p;
      for (int c = 0; c < 3; ++c) p[c] = ts.next_double("coordinate");
      v.push_back(p);
    }
    P = to_points(v, metres_per_unit(unit));
  } else if (ext == ".ply") {
    P = read_ply(path, metres_per_unit(unit), false).V;
  } else if (ext == ".obj") {
    P = read_obj(path, metres_per_unit(unit), false).V;
  } else {
    throw InputError("'" + path + "': unknown point cloud format '" + ext + "' (expected .xyz, .txt, .ply or .obj)");
  }
  if (P.rows() == 0) throw InputError(path + ": no points");
  if (!P.allFinite()) throw InputError(path + ": NaN or infinite coordinates");
  return P;
}

TetMeshFile read_tet_mesh_file(const std::string& path, LengthUnit unit) {
  const std::string ext = file_extension(path);
  const double s = metres_per_unit(unit);
  if (ext == ".vtk") return read_vtk(path, s);
  if (ext == ".mesh") return read_medit(path, s);
  throw InputError("'" + path + "': unknown tetrahedral mesh format '" + ext + "' (expected .vtk or .mesh)");
}

TetMesh read_tet_mesh(const std::string& path, LengthUnit unit) { return read_tet_mesh_file(path, unit).mesh; }

std::vector<int> cell_labels(const TetMeshFile& file, const std::string& array, const std::string& path) {
  std::string names;
  for (const auto& [n, v] : file.cell_arrays) names += (names.empty() ? "'" : ", '") + n + "'";
  if (names.empty()) names = "none";
  const std::vector<double>* values = nullptr;
  if (!array.empty()) {
    const auto it = file.cell_arrays.find(array);
    if (it == file.cell_arrays.end())
      throw InputError(path + ": no one-component cell array '" + array + "' (the file has: " + names + ")");
    values = &it->second;
  } else if (file.cell_arrays.size() == 1) {
    values = &file.cell_arrays.begin()->second;
  } else {
    throw InputError(path + ": " + (file.cell_arrays.empty() ? std::string("no cell labels (no one-component CELL_DATA array)")
                                                             : "several cell arrays (" + names + "): name the labels with prone.cell_labels"));
  }
  std::vector<int> labels(values->size());
  for (size_t t = 0; t < values->size(); ++t) {
    const double v = (*values)[t];
    if (!(std::abs(v) < 1e9) || v != std::round(v))
      throw InputError(path + ": cell label of tetrahedron " + std::to_string(t) + " is " + std::to_string(v) + ", not an integer");
    labels[t] = static_cast<int>(v);
  }
  return labels;
}

void write_tet_mesh(const std::string& path, const TetMesh& mesh, LengthUnit unit, const std::vector<int>& labels,
                    const std::string& title) {
  if (!labels.empty() && static_cast<Eigen::Index>(labels.size()) != mesh.T.rows())
    throw InputError("'" + path + "': " + std::to_string(labels.size()) + " cell labels for " + std::to_string(mesh.T.rows()) + " tetrahedra");
  const std::string ext = file_extension(path);
  const double inv = 1.0 / metres_per_unit(unit);
  if (title.find('\n') != std::string::npos) throw InputError(path + ": a VTK title is one line");
  if (ext == ".vtk") return write_vtk(path, mesh, inv, labels, title);
  if (ext == ".mesh") return write_medit(path, mesh, inv, labels);
  throw InputError("'" + path + "': unknown tetrahedral mesh format '" + ext + "' (expected .vtk or .mesh)");
}

}  // namespace btr
