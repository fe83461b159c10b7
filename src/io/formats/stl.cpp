// STL, ASCII and binary; the corners that STL repeats per triangle are merged into shared vertices.
#include "formats.h"

#include <array>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <map>
#include <sstream>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/strings.h"
#include "reading.h"

namespace btr {
namespace mesh_format {

namespace {

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

}  // namespace

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

}  // namespace mesh_format
}  // namespace btr
