#include "breast_tumour_registration/geometry/label_mesher.h"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Image_3.h>
#include <CGAL/Labeled_mesh_domain_3.h>
#include <CGAL/Mesh_3/initialize_triangulation_from_labeled_image.h>
#include <CGAL/Mesh_3/polylines_to_protect.h>
#include <CGAL/Mesh_complex_3_in_triangulation_3.h>
#include <CGAL/Mesh_criteria_3.h>
#include <CGAL/Mesh_domain_with_polyline_features_3.h>
#include <CGAL/Mesh_triangulation_3.h>
#include <CGAL/refine_mesh_3.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <iostream>
#include <limits>
#include <sstream>
#include <unordered_map>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/geometry/tetrahedralize.h"
#include "breast_tumour_registration/geometry/validation.h"

namespace btr {
namespace {
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using ImageDomain = CGAL::Labeled_mesh_domain_3<K>;
using Domain = CGAL::Mesh_domain_with_polyline_features_3<ImageDomain>;
using Tr = CGAL::Mesh_triangulation_3<Domain, CGAL::Default, CGAL::Sequential_tag>::type;
using C3t3 = CGAL::Mesh_complex_3_in_triangulation_3<Tr, Domain::Corner_index, Domain::Curve_index>;
using Criteria = CGAL::Mesh_criteria_3<Tr>;
using Patch = Domain::Surface_patch_index;  // the pair of labels on either side

std::string mm(double m) {
  std::ostringstream os;
  os.precision(3);
  os << m * 1e3 << " mm";
  return os.str();
}

// Walks the 6-connected components of the voxels whose label `accepts` takes, one label per
// component: `voxel(n)` for each voxel index of a component, then `done()`.
template <class Accepts, class Voxel, class Done>
void walk_components(const LabelVolume& v, Accepts&& accepts, Voxel&& voxel, Done&& done) {
  std::vector<char> seen(static_cast<size_t>(v.voxel_count()), 0);
  std::vector<long> stack;
  for (long start = 0; start < v.voxel_count(); ++start) {
    const int label = v.labels[start];
    if (seen[start] || !accepts(label)) continue;
    seen[start] = 1;
    stack.assign(1, start);
    while (!stack.empty()) {
      const long n = stack.back();
      stack.pop_back();
      voxel(n);
      const int i = static_cast<int>(n % v.nx), j = static_cast<int>((n / v.nx) % v.ny), k = static_cast<int>(n / (static_cast<long>(v.nx) * v.ny));
      const int d[6][3] = {{1, 0, 0}, {-1, 0, 0}, {0, 1, 0}, {0, -1, 0}, {0, 0, 1}, {0, 0, -1}};
      for (const auto& e : d) {
        const int a = i + e[0], b = j + e[1], c = k + e[2];
        if (a < 0 || b < 0 || c < 0 || a >= v.nx || b >= v.ny || c >= v.nz) continue;
        const long m = v.index(a, b, c);
        if (!seen[m] && v.labels[m] == label) {
          seen[m] = 1;
          stack.push_back(m);
        }
      }
    }
    done();
  }
}

// The 6-connected components of the voxels carrying `label` (voxel indices of each).
std::vector<std::vector<long>> label_components(const LabelVolume& v, int label) {
  std::vector<std::vector<long>> out(1);
  walk_components(
      v, [label](int l) { return l == label; }, [&](long n) { out.back().push_back(n); }, [&] { out.emplace_back(); });
  out.pop_back();
  return out;
}

// Sets to 0 in `image` the voxels of each 6-connected component of one of `labels` in `v` with
// fewer than `min_voxels` voxels; a component's voxels are kept only while it could still be a
// speck (on a 42M-voxel map, a component search per label cost 1.8 s).
void clear_specks(const LabelVolume& v, const std::set<int>& labels, long min_voxels, unsigned char* image) {
  std::vector<long> speck;
  walk_components(
      v, [&](int l) { return labels.count(l) > 0; },
      [&](long n) {
        if (static_cast<long>(speck.size()) < min_voxels) speck.push_back(n);
      },
      [&] {
        if (static_cast<long>(speck.size()) < min_voxels)
          for (long n : speck) image[n] = 0;
        speck.clear();
      });
}

// A zeroed image of bytes, nx x ny x nz voxels of `spacing`; `what` names it when memory runs out.
CGAL::Image_3 byte_image(const Eigen::Vector3i& n, const Vec3& spacing, const std::string& what) {
  _image* im = _createImage(n[0], n[1], n[2], 1, spacing[0], spacing[1], spacing[2], 1, WK_FIXED, SGN_UNSIGNED);
  if (!im) throw InputError("out of memory for " + what);
  std::fill_n(static_cast<unsigned char*>(im->data), static_cast<long>(n[0]) * n[1] * n[2], 0);
  return CGAL::Image_3(im);
}

// One component's voxels as a binary image in a box around them (3 voxels of margin);
// `first` receives the voxel index of the box's voxel (0, 0, 0).
CGAL::Image_3 component_image(const LabelVolume& v, const std::vector<long>& voxels, const Vec3& spacing, Eigen::Vector3i& first) {
  auto ijk = [&](long n) {
    return Eigen::Vector3i(static_cast<int>(n % v.nx), static_cast<int>((n / v.nx) % v.ny), static_cast<int>(n / (static_cast<long>(v.nx) * v.ny)));
  };
  Eigen::Vector3i lo = ijk(voxels[0]), hi = lo;
  for (long n : voxels) {
    lo = lo.cwiseMin(ijk(n));
    hi = hi.cwiseMax(ijk(n));
  }
  const int margin = 3;
  first = lo - Eigen::Vector3i::Constant(margin);
  const Eigen::Vector3i n = hi - lo + Eigen::Vector3i::Constant(2 * margin + 1);
  CGAL::Image_3 image = byte_image(n, spacing, "a tumour image");
  auto* data = static_cast<unsigned char*>(image.data());
  for (long m : voxels) {
    const Eigen::Vector3i q = ijk(m) - first;
    data[(static_cast<long>(q[2]) * n[1] + q[1]) * n[0] + q[0]] = 1;
  }
  return image;
}

// The first surface points of a labelled image's mesh, from rays shot inside each connected
// component of each label of `seeds` (CGAL's initialisation for labelled images; the points are
// the domain's intersections). make_mesh_3's own shoots rays from the centre of the image's box
// only, and finds none where that centre lies outside the meshed labels (air or muscle between
// or behind the breasts, a crescent-shaped tumour): it never returns.
template <class C3T3, class MeshDomain, class MeshCriteria>
void initialize_from_image(C3T3& c3t3, const MeshDomain& domain, const CGAL::Image_3& seeds, const MeshCriteria& criteria,
                           bool protect_features, const std::string& src) {
  CGAL::get_default_random() = CGAL::Random(0);  // its ray directions: one input, one mesh
  std::ostringstream chatter;  // the initialisation reports its counts on std::cout
  struct Restore {
    std::streambuf* out;
    ~Restore() { std::cout.rdbuf(out); }
  } restore{std::cout.rdbuf(chatter.rdbuf())};
  ::initialize_triangulation_from_labeled_image(c3t3, domain, seeds, criteria, static_cast<unsigned char>(0), protect_features);
  if (c3t3.triangulation().dimension() != 3)
    throw InputError(src + ": no surface points were found to start the mesh from (is the tissue thinner than a voxel?)");
}

}  // namespace

LabelledTetMesh mesh_label_volume(const LabelVolume& v, const LabelMeshOptions& opt) {
  const auto t0 = std::chrono::steady_clock::now();
  const std::string& src = opt.source;
  auto positive = [&](double x, const char* name) {
    if (!(x > 0) || !std::isfinite(x)) throw InputError(src + ": " + name + " must be positive, got " + std::to_string(x));
  };
  positive(opt.cell_size, "cell_size");
  positive(opt.tumour_facet_size, "tumour_facet_size");
  positive(opt.facet_distance_ratio, "facet_distance_ratio");
  if (!(opt.radius_edge_ratio >= 1.0)) throw InputError(src + ": radius_edge_ratio must be >= 1");
  if (!(opt.max_anisotropy >= 1.0)) throw InputError(src + ": max_anisotropy must be >= 1");
  if (static_cast<long>(v.labels.size()) != v.voxel_count() || v.nx < 2 || v.ny < 2 || v.nz < 2)
    throw InputError(src + ": the label map's size and its labels do not agree");
  if (opt.tissue.empty() && opt.tumour.empty()) throw InputError(src + ": no label is meshed as tissue");
  for (int l : opt.tissue)
    if (l <= 0 || l > 255 || l == opt.muscle) throw InputError(src + ": tissue label " + std::to_string(l) + " is not a tissue label value (1 to 255, not the muscle)");
  for (int l : opt.tumour)
    if (l <= 0 || l > 255 || l == opt.muscle) throw InputError(src + ": tumour label " + std::to_string(l) + " is not a label value (1 to 255, not the muscle)");

  const Vec3 spacing = v.spacing();
  const double anisotropy = spacing.maxCoeff() / spacing.minCoeff();
  if (anisotropy > opt.max_anisotropy)
    throw InputError(src + ": voxels of " + mm(spacing[0]) + " x " + mm(spacing[1]) + " x " + mm(spacing[2]) +
                     " are too anisotropic to mesh the skin faithfully (ratio " + std::to_string(anisotropy) + ", at most " +
                     std::to_string(opt.max_anisotropy) +
                     "); resample the label map to near-isotropic voxels (e.g. Slicer's Resample Scalar Volume)");
  if (spacing.maxCoeff() > opt.cell_size)
    throw InputError(src + ": voxels of up to " + mm(spacing.maxCoeff()) + " are coarser than the cell size " +
                     mm(opt.cell_size) + "; the segmentation cannot carry a mesh this fine (use a larger cell size or finer voxels)");

  // Which labels are there, and what each becomes.
  const std::vector<long> hist = label_histogram(v);
  std::set<int> meshed = opt.tissue;
  meshed.insert(opt.tumour.begin(), opt.tumour.end());
  auto name_of = [&](int l) {
    auto it = v.names.find(l);
    return "label " + std::to_string(l) + (it != v.names.end() ? " ('" + it->second + "')" : std::string());
  };
  for (int l : opt.tumour)
    if (hist[l] == 0) throw InputError(src + ": the tumour " + name_of(l) + " has no voxels (an empty tumour segment; check the label table)");
  if (opt.muscle > 0 && hist[opt.muscle] == 0)
    throw InputError(src + ": the muscle " + name_of(opt.muscle) + " has no voxels; give the right label, or none to fix the posterior plane");
  long tissue_voxels = 0;
  for (int l : meshed) tissue_voxels += hist[l];
  if (tissue_voxels == 0) throw InputError(src + ": no voxel carries a tissue label; check the label table against the file");

  const double voxel_volume = spacing.prod();
  const double estimate = 4.3 * tissue_voxels * voxel_volume / std::pow(opt.cell_size, 3);
  if (estimate > kMaxTetrahedra)
    throw InputError(src + ": a cell size of " + mm(opt.cell_size) + " would make about " + std::to_string(static_cast<long>(estimate)) +
                     " tetrahedra, more than the " + std::to_string(static_cast<long>(kMaxTetrahedra)) + " this package budgets");

  // The image Mesh_3 sees: tissue and tumour labels as they are, the muscle as itself (outside,
  // but its interface is told apart), everything else 0 (outside).
  const Eigen::Vector3i voxels(v.nx, v.ny, v.nz);
  CGAL::Image_3 image = byte_image(voxels, spacing, src + "'s meshing image");
  auto* data = static_cast<unsigned char*>(image.data());
  for (int k = 0; k < v.nz; ++k)
    for (int j = 0; j < v.ny; ++j)
      for (int i = 0; i < v.nx; ++i) {
        const long n = v.index(i, j, k);
        const int l = v.labels[n];
        data[n] = (meshed.count(l) || l == opt.muscle) ? static_cast<unsigned char>(l) : 0;
      }

  // The simulation mesh: one size everywhere (the presets compare mesh sizes by the mean edge;
  // the tumours' detail goes into their own surfaces, below).
  const int muscle = opt.muscle;
  CGAL::Random rng(0);  // one input, one mesh
  namespace p = CGAL::parameters;
  Domain domain = Domain::create_labeled_image_mesh_domain(
      image, p::relative_error_bound = 1e-6, p::p_rng = &rng,
      p::null_subdomain_index = [muscle](int l) { return l == 0 || (muscle > 0 && l == muscle); });
  if (opt.protect_features) {
    std::vector<std::vector<K::Point_3>> polylines;
    CGAL::polylines_to_protect<K::Point_3, unsigned char>(image, polylines);
    domain.add_features(polylines.begin(), polylines.end());
  }
  Criteria criteria(p::edge_size = opt.cell_size, p::facet_angle = opt.facet_angle, p::facet_size = opt.cell_size,
                    p::facet_distance = opt.facet_distance_ratio * opt.cell_size,
                    p::cell_radius_edge_ratio = opt.radius_edge_ratio, p::cell_size = opt.cell_size);
  // The seeds: the meshing image without the specks of a tissue label smaller than an eighth of
  // a cell. Every speck starts rays whose points, close together, the mesh keeps: SfePy's body
  // as a label map (a blocky gland) had twice the tetrahedra, one of them flat. Seeding from the
  // largest body of tissue alone misses the subdomains inside it (the tumours).
  const long min_voxels = std::max(1L, static_cast<long>(std::pow(0.5 * opt.cell_size, 3) / voxel_volume));
  CGAL::Image_3 seeds = byte_image(voxels, spacing, src + "'s seed image");
  auto* seed_data = static_cast<unsigned char*>(seeds.data());
  std::copy(data, data + v.voxel_count(), seed_data);
  clear_specks(v, meshed, min_voxels, seed_data);
  C3t3 c3t3;
  initialize_from_image(c3t3, domain, seeds, criteria, opt.protect_features, src);
  // As in tetrahedralize(): optimisers without time limits, so that one input gives one mesh.
  // Not reset: that would drop the weights of the protected lines' balls.
  CGAL::refine_mesh_3(c3t3, domain, criteria, p::no_lloyd(), p::no_odt(), p::perturb(p::time_limit = 0.0, p::sliver_bound = 10.0),
                      p::exude(p::time_limit = 0.0, p::sliver_bound = 10.0), p::no_reset_c3t3());

  // Image coordinates -> RAS.
  const Mat3 to_ras = v.ijk_to_ras * spacing.cwiseInverse().asDiagonal();
  auto ras = [&](const Tr::Vertex_handle& h) {
    const auto& q = h->point().point();
    return Vec3(v.origin + to_ras * Vec3(q.x(), q.y(), q.z()));
  };
  LabelledTetMesh out;
  std::unordered_map<Tr::Vertex_handle, int> index;
  std::vector<Vec3> verts;
  auto vertex_index = [&](const Tr::Vertex_handle& h) {
    auto it = index.find(h);
    if (it == index.end()) {
      it = index.emplace(h, static_cast<int>(verts.size())).first;
      verts.push_back(ras(h));
    }
    return it->second;
  };
  std::vector<Eigen::Vector4i> tets;
  for (auto c = c3t3.cells_in_complex_begin(); c != c3t3.cells_in_complex_end(); ++c) {
    Eigen::Vector4i t;
    for (int k = 0; k < 4; ++k) t[k] = vertex_index(c->vertex(k));
    tets.push_back(t);
    out.labels.push_back(c3t3.subdomain_index(c));
  }
  if (tets.empty())
    throw InputError(src + ": Mesh_3 made no tetrahedra (is the tissue smaller than the cell size " + mm(opt.cell_size) + "?)");
  out.mesh.V.resize(static_cast<Eigen::Index>(verts.size()), 3);
  for (size_t i = 0; i < verts.size(); ++i) out.mesh.V.row(static_cast<Eigen::Index>(i)) = verts[i].transpose();
  out.mesh.T.resize(static_cast<Eigen::Index>(tets.size()), 4);
  for (size_t i = 0; i < tets.size(); ++i) {
    const auto r = static_cast<Eigen::Index>(i);
    out.mesh.T.row(r) = tets[i].transpose();
    if (tet_signed_volume(out.mesh.V, out.mesh.T, r) < 0) std::swap(out.mesh.T(r, 2), out.mesh.T(r, 3));
  }

  // Interfaces: the chest wall (with the muscle) and the tumours' surfaces (oriented away
  // from the tumour cell).
  std::vector<char> on_muscle(verts.size(), 0), on_boundary(verts.size(), 0);
  for (auto f = c3t3.facets_in_complex_begin(); f != c3t3.facets_in_complex_end(); ++f) {
    const Patch patch = c3t3.surface_patch_index(*f);
    const Tr::Facet facet = *f;
    const int a = patch.first, b = patch.second;
    const bool a_in = meshed.count(a) > 0, b_in = meshed.count(b) > 0;
    if (!a_in && !b_in) continue;  // e.g. muscle against air: no tetrahedron on either side
    if (a_in != b_in) {  // the body's boundary: skin, or chest wall where the other side is muscle
      const int other = a_in ? b : a;
      for (int k = 0; k < 4; ++k)
        if (k != facet.second) {
          const int vi = vertex_index(facet.first->vertex(k));
          on_boundary[vi] = 1;
          if (muscle > 0 && other == muscle) on_muscle[vi] = 1;
        }
    }
  }
  for (size_t i = 0; i < verts.size(); ++i)
    if (on_muscle[i]) out.chest_wall.push_back(static_cast<int>(i));
  out.chest_wall_from_muscle = !out.chest_wall.empty();
  if (muscle > 0 && out.chest_wall.empty())
    throw InputError(src + ": the muscle " + name_of(muscle) + " touches no tissue, so there is no chest wall to fix");
  if (muscle <= 0) {
    const Vec3 dir = opt.posterior.normalized();
    double deepest = -std::numeric_limits<double>::infinity();
    for (size_t i = 0; i < verts.size(); ++i)
      if (on_boundary[i]) deepest = std::max(deepest, verts[i].dot(dir));
    for (size_t i = 0; i < verts.size(); ++i)
      if (on_boundary[i] && verts[i].dot(dir) >= deepest - 0.5 * opt.cell_size) out.chest_wall.push_back(static_cast<int>(i));
  }
  if (out.chest_wall.size() < 3) throw InputError(src + ": fewer than 3 chest-wall vertices were found");

  // Each tumour label meshed on its own, finely, in a box around it: its surface's connected
  // components are the tumours (the simulation mesh keeps the label for the materials).
  for (int label : opt.tumour) {
    std::vector<std::vector<long>> comps = label_components(v, label);
    std::sort(comps.begin(), comps.end(), [](const auto& x, const auto& y) { return x.size() > y.size(); });
    for (const auto& voxels : comps) {
      Eigen::Vector3i first;
      CGAL::Image_3 sub = component_image(v, voxels, spacing, first);
      CGAL::Random sub_rng(0);
      ImageDomain sub_domain = ImageDomain::create_labeled_image_mesh_domain(sub, p::relative_error_bound = 1e-6, p::p_rng = &sub_rng);
      using SubTr = CGAL::Mesh_triangulation_3<ImageDomain, CGAL::Default, CGAL::Sequential_tag>::type;
      using SubC3t3 = CGAL::Mesh_complex_3_in_triangulation_3<SubTr>;
      CGAL::Mesh_criteria_3<SubTr> sub_criteria(p::facet_angle = opt.facet_angle, p::facet_size = opt.tumour_facet_size,
                                                p::facet_distance = 0.1 * opt.tumour_facet_size,
                                                p::cell_radius_edge_ratio = opt.radius_edge_ratio);
      SubC3t3 sc;
      initialize_from_image(sc, sub_domain, sub, sub_criteria, false, src);
      CGAL::refine_mesh_3(sc, sub_domain, sub_criteria, p::no_lloyd(), p::no_odt(), p::no_perturb(), p::no_exude(), p::no_reset_c3t3());
      auto to_ras_sub = [&](const SubTr::Vertex_handle& h) {
        const auto& q = h->point().point();
        return Vec3(v.origin + v.ijk_to_ras * (Vec3(q.x(), q.y(), q.z()).cwiseQuotient(spacing) + first.cast<double>()));
      };
      LabelledTetMesh::Tumour tumour;
      tumour.label = label;
      std::unordered_map<SubTr::Vertex_handle, int> sub_index;
      std::vector<Vec3> pts;
      std::vector<Eigen::Vector3i> faces;
      for (auto f = sc.facets_in_complex_begin(); f != sc.facets_in_complex_end(); ++f) {
        SubTr::Facet facet = *f;  // oriented from the tumour's cell, away from its 4th vertex
        if (!sc.is_in_complex(facet.first)) facet = sc.triangulation().mirror_facet(facet);
        Eigen::Vector3i t;
        for (int k = 0, m = 0; k < 4; ++k)
          if (k != facet.second) {
            auto [it, fresh] = sub_index.emplace(facet.first->vertex(k), static_cast<int>(pts.size()));
            if (fresh) pts.push_back(to_ras_sub(facet.first->vertex(k)));
            t[m++] = it->second;
          }
        const Vec3 nrm = (pts[t[1]] - pts[t[0]]).cross(pts[t[2]] - pts[t[0]]);
        if (nrm.dot(to_ras_sub(facet.first->vertex(facet.second)) - pts[t[0]]) > 0) std::swap(t[1], t[2]);
        faces.push_back(t);
      }
      if (faces.size() < 4)
        throw InputError(src + ": a tumour of " + name_of(label) + " (" + std::to_string(voxels.size()) +
                         " voxels) is too small to mesh at a facet size of " + mm(opt.tumour_facet_size) +
                         "; use a smaller tumour facet size or remove the speck from the segmentation");
      tumour.surface.V.resize(static_cast<Eigen::Index>(pts.size()), 3);
      for (size_t i = 0; i < pts.size(); ++i) tumour.surface.V.row(static_cast<Eigen::Index>(i)) = pts[i].transpose();
      tumour.surface.F.resize(static_cast<Eigen::Index>(faces.size()), 3);
      for (size_t f = 0; f < faces.size(); ++f) tumour.surface.F.row(static_cast<Eigen::Index>(f)) = faces[f].transpose();
      out.tumours.push_back(std::move(tumour));
    }
  }
  out.seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  return out;
}

}  // namespace btr
