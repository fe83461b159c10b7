// Legacy VTK unstructured grid (ASCII): points, tetrahedral cells, one-component cell data.
#include "formats.h"

#include <map>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/strings.h"
#include "reading.h"

namespace btr {
namespace mesh_format {

namespace {

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

}  // namespace

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

}  // namespace mesh_format
}  // namespace btr
