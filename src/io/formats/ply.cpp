// PLY, ASCII and binary little-endian: vertex x y z and face vertex_indices; other properties are read past.
#include "formats.h"

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <sstream>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/strings.h"
#include "reading.h"

namespace btr {
namespace mesh_format {

namespace {

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

}  // namespace

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
  write_vertex_and_triangle_rows(out, m, inv);
}

}  // namespace mesh_format
}  // namespace btr
