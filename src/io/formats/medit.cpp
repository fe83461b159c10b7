// Medit .mesh (ASCII): vertices, tetrahedra with their element references; other blocks skipped.
#include "formats.h"

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/strings.h"
#include "reading.h"

namespace btr {
namespace mesh_format {

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

}  // namespace mesh_format
}  // namespace btr
