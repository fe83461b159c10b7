#include "breast_tumour_registration/geometry/tetrahedralize.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/Polyhedral_mesh_domain_with_features_3.h>
#include <CGAL/Surface_mesh.h>
#include <CGAL/make_mesh_3.h>

#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <vector>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/geometry/metrics.h"
#include "breast_tumour_registration/geometry/validation.h"

namespace btr {
namespace {
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using CgalSurface = CGAL::Surface_mesh<K::Point_3>;
using Domain = CGAL::Polyhedral_mesh_domain_with_features_3<K, CgalSurface>;
using Tr = CGAL::Mesh_triangulation_3<Domain, CGAL::Default, CGAL::Sequential_tag>::type;
using C3t3 = CGAL::Mesh_complex_3_in_triangulation_3<Tr, Domain::Corner_index, Domain::Curve_index>;
using Criteria = CGAL::Mesh_criteria_3<Tr>;

// A refinement ball's size bound at `distance` from its centre (before the global cap).
double graded_size(const MeshRefinement& b, double distance, double grading) {
  return b.cell_size + grading * std::max(0.0, distance - b.radius);
}

/// cell_size_at as CGAL's MeshDomainField_3.
struct CellSizeField {
  using FT = K::FT;
  using Point_3 = K::Point_3;
  using Index = Domain::Index;
  const TetrahedralizeOptions* opt;
  FT operator()(const Point_3& p, const int, const Index&) const { return cell_size_at(Vec3(p.x(), p.y(), p.z()), *opt); }
};
}  // namespace

double cell_size_at(const Vec3& x, const TetrahedralizeOptions& opt) {
  double s = opt.cell_size;
  for (const MeshRefinement& b : opt.refinements) s = std::min(s, graded_size(b, (x - b.centre).norm(), opt.refinement_grading));
  return s;
}

TetMesh tetrahedralize(const SurfaceMesh& surface, const TetrahedralizeOptions& opt) {
  if (!(opt.cell_size > 0) || !std::isfinite(opt.cell_size))
    throw InputError("tetrahedralize: cell_size must be positive (metres), got " + std::to_string(opt.cell_size));
  if (!(opt.radius_edge_ratio >= 1.0))
    throw InputError("tetrahedralize: radius_edge_ratio must be >= 1 (2 guarantees termination)");
  if (!(opt.facet_distance_ratio > 0)) throw InputError("tetrahedralize: facet_distance_ratio must be positive");
  if (surface.F.rows() < 4)  // CGAL's domain dereferences the faces' bounding tree: an empty one crashed it
    throw InputError("tetrahedralize: the surface has " + std::to_string(surface.F.rows()) +
                     " faces; a closed surface has at least 4");
  // Memory budget, checked before meshing (issue 11: --cell-size 0.5 grew without limit).
  // CGAL makes about 4.3 V / c^3 tetrahedra at cell size c (34.7k for the 0.84 L phantom at
  // 4.7 mm); each costs about 1 kB through meshing, assembly and factorization.
  for (const MeshRefinement& b : opt.refinements)
    if (!(b.cell_size > 0) || !(b.cell_size <= opt.cell_size) || !(b.radius >= 0) || !b.centre.allFinite())
      throw InputError("tetrahedralize: a refinement needs a finite centre, a radius >= 0 and a cell size in (0, cell_size]");
  if (!opt.refinements.empty() && !(opt.refinement_grading > 0))
    throw InputError("tetrahedralize: refinement_grading must be positive");
  const double volume = std::abs(enclosed_volume(surface));
  const double uniform = 4.3 * volume / std::pow(opt.cell_size, 3);  // without the balls
  double estimate = uniform;
  // Each ball and its graded shell, as if it lay inside the volume (an upper estimate): the
  // size grows linearly from the ball's to the global one over (h - c) / grading.
  for (const MeshRefinement& b : opt.refinements) {
    const double shell = (opt.cell_size - b.cell_size) / opt.refinement_grading;
    const int n = 64;
    for (int k = 0; k < n; ++k) {  // midpoint rule over the radius
      const double r = (b.radius + shell) * (k + 0.5) / n;
      const double size = std::min(opt.cell_size, graded_size(b, r, opt.refinement_grading));
      const double dv = 4 * M_PI * r * r * (b.radius + shell) / n;
      estimate += 4.3 * dv * (1 / std::pow(size, 3) - 1 / std::pow(opt.cell_size, 3));
    }
  }
  if (estimate > kMaxTetrahedra) {
    const std::string budget = " tetrahedra, more than the " + std::to_string(static_cast<long>(kMaxTetrahedra)) +
                               " this package budgets (about 3 GB); ";
    if (uniform <= kMaxTetrahedra) {  // the refinement balls make it
      double finest = opt.cell_size;
      for (const MeshRefinement& b : opt.refinements) finest = std::min(finest, b.cell_size);
      const size_t n = opt.refinements.size();
      throw InputError("tetrahedralize: refinement balls with cells of " + std::to_string(finest * 1e3) + " mm (" +
                       std::to_string(n) + (n == 1 ? " ball" : " balls") + ", graded to " +
                       std::to_string(opt.cell_size * 1e3) + " mm) would make about " +
                       std::to_string(static_cast<long>(estimate)) + budget + "use larger cells in the balls");
    }
    throw InputError("tetrahedralize: a cell size of " + std::to_string(opt.cell_size * 1e3) + " mm would make about " +
                     std::to_string(static_cast<long>(estimate)) + budget + "use at least " +
                     std::to_string(std::cbrt(4.3 * volume / kMaxTetrahedra) * 1e3) + " mm");
  }

  CgalSurface sm;
  std::vector<CgalSurface::Vertex_index> vi(surface.V.rows());
  for (Eigen::Index i = 0; i < surface.V.rows(); ++i)
    vi[i] = sm.add_vertex(K::Point_3(surface.V(i, 0), surface.V(i, 1), surface.V(i, 2)));
  for (Eigen::Index f = 0; f < surface.F.rows(); ++f)
    if (sm.add_face(vi[surface.F(f, 0)], vi[surface.F(f, 1)], vi[surface.F(f, 2)]) == CgalSurface::null_face())
      throw InputError("tetrahedralize: face " + std::to_string(f) + " makes the surface non-manifold");

  Domain domain(sm);
  domain.detect_features(opt.feature_angle);
  const double h = opt.cell_size;
  namespace p = CGAL::parameters;
  // A constant size where nothing is refined (the field would give the same bound, but CGAL's
  // meshes are kept as they were, bit for bit).
  auto criteria_with = [&](const auto& cell_size) {
    return Criteria(p::edge_size = h, p::facet_angle = opt.facet_angle, p::facet_size = h,
                    p::facet_distance = opt.facet_distance_ratio * h, p::cell_radius_edge_ratio = opt.radius_edge_ratio,
                    p::cell_size = cell_size);
  };
  const Criteria criteria = opt.refinements.empty() ? criteria_with(h) : criteria_with(CellSizeField{&opt});
  // The optimisers' time limits default to the measured refinement time, which made one input
  // give several meshes (issue 11). Without a time limit they stop when every dihedral angle
  // is above 10 deg (or nothing improves), and the domain's random generator is seeded
  // (Random(0)), so one input gives one mesh. Measured on the 6k-vertex phantom surface:
  // 0.31 s at 4.7 mm (no bound: 2.8 s; CGAL's time limits: about 0.5 s).
  C3t3 c3t3 = opt.optimize ? CGAL::make_mesh_3<C3t3>(domain, criteria, p::no_lloyd(), p::no_odt(),
                                                     p::perturb(p::time_limit = 0.0, p::sliver_bound = 10.0),
                                                     p::exude(p::time_limit = 0.0, p::sliver_bound = 10.0))
                           : CGAL::make_mesh_3<C3t3>(domain, criteria, p::no_lloyd(), p::no_odt(), p::no_perturb(), p::no_exude());

  TetMesh out;
  std::unordered_map<Tr::Vertex_handle, int> index;
  std::vector<Vec3> verts;
  std::vector<Eigen::Vector4i> tets;
  for (auto c = c3t3.cells_in_complex_begin(); c != c3t3.cells_in_complex_end(); ++c) {
    Eigen::Vector4i t;
    for (int k = 0; k < 4; ++k) {
      auto v = c->vertex(k);
      auto it = index.find(v);
      if (it == index.end()) {
        const auto& p3 = v->point().point();
        it = index.emplace(v, static_cast<int>(verts.size())).first;
        verts.emplace_back(p3.x(), p3.y(), p3.z());
      }
      t[k] = it->second;
    }
    tets.push_back(t);
  }
  if (tets.empty()) throw InputError("tetrahedralize: Mesh_3 produced no tetrahedra (is the surface closed, and is cell_size smaller than the object?)");
  out.V.resize(verts.size(), 3);
  for (size_t i = 0; i < verts.size(); ++i) out.V.row(i) = verts[i].transpose();
  out.T.resize(tets.size(), 4);
  for (size_t i = 0; i < tets.size(); ++i) {
    out.T.row(i) = tets[i].transpose();
    if (tet_signed_volume(out.V, out.T, static_cast<Eigen::Index>(i)) < 0) std::swap(out.T(i, 2), out.T(i, 3));
  }
  return out;
}

TetQuality tet_quality(const TetMesh& m) {
  TetQuality q;
  std::vector<double> ratios(m.T.rows());
  q.min_dihedral_deg = 180;
  q.min_volume = std::numeric_limits<double>::max();
  for (Eigen::Index t = 0; t < m.T.rows(); ++t) {
    Vec3 p[4];
    for (int k = 0; k < 4; ++k) p[k] = m.V.row(m.T(t, k));
    // Circumradius from the standard formula |a|^2 (b x c) + |b|^2 (c x a) + |c|^2 (a x b) over 2 a.(b x c).
    const Vec3 a = p[1] - p[0], b = p[2] - p[0], c = p[3] - p[0];
    const double den = 2.0 * a.dot(b.cross(c));
    const Vec3 num = a.squaredNorm() * b.cross(c) + b.squaredNorm() * c.cross(a) + c.squaredNorm() * a.cross(b);
    const double R = std::abs(den) > 0 ? num.norm() / std::abs(den) : std::numeric_limits<double>::infinity();
    double lmin = std::numeric_limits<double>::max();
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) lmin = std::min(lmin, (p[i] - p[j]).norm());
    ratios[t] = R / lmin;
    q.min_volume = std::min(q.min_volume, den / 12.0);
    // Dihedral angles along each edge (i,j): angle between the faces containing it.
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) {
        int o[2], n = 0;
        for (int k = 0; k < 4; ++k)
          if (k != i && k != j) o[n++] = k;
        const Vec3 e = (p[j] - p[i]).normalized();
        Vec3 u = p[o[0]] - p[i], w = p[o[1]] - p[i];
        u -= u.dot(e) * e;
        w -= w.dot(e) * e;
        const double cosang = std::clamp(u.normalized().dot(w.normalized()), -1.0, 1.0);
        q.min_dihedral_deg = std::min(q.min_dihedral_deg, std::acos(cosang) * 180.0 / M_PI);
      }
  }
  if (!ratios.empty()) {
    std::vector<double> s = ratios;
    std::nth_element(s.begin(), s.begin() + s.size() / 2, s.end());
    q.median_radius_edge = s[s.size() / 2];
    q.max_radius_edge = *std::max_element(ratios.begin(), ratios.end());
  }
  return q;
}

}  // namespace btr
