#include "breast_tumour_registration/io/scene.h"

#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cstdio>
#include <cmath>
#include <filesystem>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/units.h"
#include "breast_tumour_registration/fem/material_region.h"
#include "breast_tumour_registration/fem/stable_neo_hookean.h"
#include "breast_tumour_registration/fem/element_order.h"
#include "breast_tumour_registration/fem/volume_form.h"
#include "breast_tumour_registration/geometry/surface_attachment.h"
#include "breast_tumour_registration/geometry/surface_orientation.h"
#include "breast_tumour_registration/geometry/validation.h"
#include "breast_tumour_registration/io/index_io.h"
#include "breast_tumour_registration/io/markups_io.h"
#include "breast_tumour_registration/io/mesh_io.h"
#include "breast_tumour_registration/io/yaml_fields.h"

namespace btr {
namespace fs = std::filesystem;

Rigid misalignment_from_degrees_mm(const Vec3& rotation_deg, const Vec3& translation_mm) {
  return rigid_from_rpy(translation_mm * 1e-3, rotation_deg * M_PI / 180.0);
}

void apply_misalignment(Scene& s, const Rigid& m) {
  if (s.supine_surface) s.supine_surface = transform_surface(m, *s.supine_surface);
  if (s.supine_cloud) s.supine_cloud = transform_points(m, *s.supine_cloud);
  if (s.supine_rigid) s.supine_rigid = transform_surface(m, *s.supine_rigid);
  if (s.landmark_supine.rows()) s.landmark_supine = transform_points(m, s.landmark_supine);
  for (auto& t : s.tumours)
    if (t.supine_ground_truth) t.supine_ground_truth = transform_surface(m, *t.supine_ground_truth);
  s.misalignment = m * s.misalignment;
}

namespace {
// Every key a scene may have; the informational ones (frame, rest, landmark_set,
// landmark_vertices, generator, supine.tet_mesh_ground_truth) are written by btr_phantom.
const std::vector<std::string> kSceneKeys = {
    "units", "frame", "prone", "prone.tet_mesh", "prone.surface", "prone.cell_size_mm", "prone.tumour_cell_size_mm", "rest", "rest.tet_mesh",
    "rest.surface", "chest_wall", "chest_ring", "landmarks", "landmarks.prone", "landmarks.supine", "patient_frame", "landmark_set", "landmark_vertices.*", "supine",
    "supine.surface", "supine.denoise", "supine.cloud", "supine.chest_ring", "supine.tet_mesh_ground_truth", "tumours", "tumours[]",
    "tumours[].name", "tumours[].prone", "tumours[].supine_ground_truth", "tumours[].rest", "material",
    "material.youngs_modulus", "material.youngs_modulus_range", "material.poisson_ratio", "material.density", "material.volume_form", "material.nodal_element_share", "material.nodal_fallback", "material.unload_element_order", "regions", "regions[]",
    "regions[].name", "regions[].youngs_modulus", "regions[].relative_stiffness", "regions[].label", "regions[].surface", "prone.cell_labels", "tumour_material",
    "tumour_material.youngs_modulus", "gravity", "prone_gravity", "steps", "preset", "misalignment", "misalignment.rotation_deg",
    "misalignment.translation_mm", "uncertainty", "uncertainty.youngs_modulus_range", "uncertainty.poisson_ratio_range",
    "uncertainty.gravity_direction_deg", "uncertainty.landmark_sd_mm", "uncertainty.depth_noise_mm", "uncertainty.rigid_pose", "uncertainty.discretisation", "generator.*"};

Scene load_scene_fields(const std::string& path);
}  // namespace

Scene load_scene(const std::string& path) {
  Scene s;
  try {
    s = load_scene_fields(path);
  } catch (const YAML::Exception& e) {  // a field read without a named check: still the file's fault
    throw InputError(path + ": " + e.what());
  }
  return s;
}

void check_landmark_attachment(const BoundaryAttachment& a, const std::vector<std::string>& labels, const std::string& path) {
  for (size_t i = 0; i < a.distances.size(); ++i)
    if (a.distances[i] > kMaxLandmarkSkinDistance) {
      const std::string name = i < labels.size() ? "'" + labels[i] + "'" : std::to_string(i);
      char buf[96];
      std::snprintf(buf, sizeof buf, " is %.1f mm from the prone skin (at most %.0f mm)", a.distances[i] * 1e3, kMaxLandmarkSkinDistance * 1e3);
      throw InputError(path + ": field 'landmarks': prone landmark " + name + buf +
                       ": is the point list's coordinate system (LPS/RAS) or the scene's patient_frame wrong?");
    }
}

void check_length_scale(const Points& V, LengthUnit units, const std::string& file, const std::string& field) {
  const double extent = (V.colwise().maxCoeff() - V.colwise().minCoeff()).norm();
  if (extent < 0.01 || extent > 3.0)
    throw InputError(file + ": field '" + field + "': the mesh spans " + std::to_string(extent) + " m with units: " +
                     to_string(units) + "; a breast spans 0.05 to 0.5 m: is `units` right (mm or m)?");
}

namespace {
Scene load_scene_fields(const std::string& path) {
  const YamlFields c{path, fs::path(path).parent_path()};
  const YAML::Node root = YamlFields::load_mapping(path, "scene");
  c.check_keys(root, kSceneKeys);
  Scene s;
  s.path = path;
  s.units = c.length_unit(root);

  // Prone model.
  const YAML::Node prone = root["prone"];
  if (!prone || !prone.IsMap()) c.fail("prone", "missing; give prone.tet_mesh or prone.surface");
  SurfaceMesh prone_surface;
  bool have_surface = false;
  // The size a prone surface is meshed at, or the size a prone tetrahedral mesh was made at.
  std::optional<double> stated_cell;
  if (prone["cell_size_mm"]) {
    stated_cell = mm_to_m(c.number(prone["cell_size_mm"], "prone.cell_size_mm"));
    if (!(*stated_cell > 0) || !std::isfinite(*stated_cell)) c.fail("prone.cell_size_mm", "must be positive");
  }
  if (prone["surface"]) {
    prone_surface = c.load("prone.surface", [&] { return read_surface(c.path_of(prone["surface"], "prone.surface"), s.units); });
    check_length_scale(prone_surface.V, s.units, path, "prone.surface");
    have_surface = true;
  }
  TetMeshFile prone_file;  // with its cell data, for the regions' labels
  if (prone["tet_mesh"]) {
    prone_file = c.load("prone.tet_mesh", [&] { return read_tet_mesh_file(c.path_of(prone["tet_mesh"], "prone.tet_mesh"), s.units); });
    s.prone = c.load("prone.tet_mesh", [&] {
      TetMesh m = prone_file.mesh;
      orient_tets_positive(m);  // reorders each tetrahedron's corners, not the tetrahedra: the labels keep
      validate_tet_mesh(m, "prone.tet_mesh");
      return m;
    });
    check_length_scale(s.prone.V, s.units, path, "prone.tet_mesh");
    s.prone_mesh_cell_size = stated_cell;
  } else if (have_surface) {
    // Meshed by mesh_prone (below, or by the caller at the size its preset simulates).
    c.load("prone.surface", [&] {
      repair_orientation(prone_surface, "prone.surface", s.warnings);
      validate_surface(prone_surface, "prone.surface");
      return 0;
    });
    s.prone_source = ProneSurfaceSource{};
    s.prone_source->surface = prone_surface;
    s.prone_source->cell_size = stated_cell;
  } else {
    c.fail("prone", "give prone.tet_mesh or prone.surface");
  }
  if (prone["tumour_cell_size_mm"]) {
    const double cell = mm_to_m(c.number(prone["tumour_cell_size_mm"], "prone.tumour_cell_size_mm"));
    if (!(cell >= 0) || !std::isfinite(cell)) c.fail("prone.tumour_cell_size_mm", "must be 0 (none) or a positive size");
    s.tumour_cell_size = cell;
  }
  if (prone["cell_labels"] && !prone["tet_mesh"]) c.fail("prone.cell_labels", "only with prone.tet_mesh (the file holding them)");

  // Chest wall: tet vertex indices, or surface indices re-attached after tetrahedralization.
  if (!root["chest_wall"]) c.fail("chest_wall", "missing: the fixed chest-wall vertices are required");
  const std::vector<int> wall = c.load("chest_wall", [&] { return read_index_list(c.path_of(root["chest_wall"], "chest_wall")); });
  if (s.prone_source) {
    c.load("chest_wall", [&] { check_index_range(wall, prone_surface.V.rows(), "chest_wall"); return 0; });
    s.prone_source->chest_wall = wall;
  } else {
    c.load("chest_wall", [&] { check_index_range(wall, s.prone.V.rows(), "chest_wall"); return 0; });
    s.chest_wall = wall;
  }

  // Supine data (loaded in the supine frame; the misalignment is applied afterwards).
  const YAML::Node supine = root["supine"];
  if (supine && supine["surface"]) {
    s.supine_surface = c.load("supine.surface", [&] {
      SurfaceMesh m = read_surface(c.path_of(supine["surface"], "supine.surface"), s.units);
      SurfaceCheckOptions o;
      o.require_closed = false;  // a scan may be open
      o.require_consistent_orientation = false;
      validate_surface(m, "supine.surface", o);
      return m;
    });
  }
  if (supine && supine["denoise"]) {
    const std::string d = c.text(supine["denoise"], "supine.denoise");
    if (d != "auto" && d != "off") c.fail("supine.denoise", "expected auto or off, got '" + d + "'");
    if (!s.supine_surface) c.fail("supine.denoise", "denoising is for a supine.surface; there is none");
    s.supine_denoise = d == "auto";
  }
  if (supine && supine["cloud"]) {
    if (s.supine_surface) c.fail("supine.cloud", "give supine.surface or supine.cloud, not both");
    s.supine_cloud = c.load("supine.cloud", [&] { return read_point_cloud(c.path_of(supine["cloud"], "supine.cloud"), s.units); });
  }
  // Rigid regions may be open; they are checked at load (a NaN used to surface only in ICP).
  auto open_surface = [&](const YAML::Node& n, const std::string& field) {
    return c.load(field, [&] {
      SurfaceMesh m = read_surface(c.path_of(n, field), s.units);
      SurfaceCheckOptions o;
      o.require_closed = false;
      o.require_consistent_orientation = false;
      validate_surface(m, field, o);
      return m;
    });
  };
  if (supine && supine["chest_ring"]) s.supine_rigid = open_surface(supine["chest_ring"], "supine.chest_ring");
  if (root["chest_ring"]) s.prone_rigid = open_surface(root["chest_ring"], "chest_ring");

  // The patient frame of the scene's coordinates (RAS or LPS), when it says: point lists are
  // converted to it, and the outputs for 3D Slicer are written from it.
  if (root["patient_frame"])
    s.patient_frame = c.load("patient_frame", [&] { return parse_patient_frame(c.text(root["patient_frame"], "patient_frame"), "patient_frame"); });
  // Landmarks: Slicer point lists matched by label, or a file of vertex index pairs.
  if (root["landmarks"] && root["landmarks"].IsMap()) {
    const YAML::Node lm = root["landmarks"];
    if (!lm["prone"] || !lm["supine"]) c.fail("landmarks", "give both landmarks.prone and landmarks.supine (Slicer .mrk.json or .fcsv)");
    if (!root["patient_frame"])
      c.fail("patient_frame", "missing: with Slicer point lists the scene must say in which patient frame its own coordinates are "
                              "(patient_frame: RAS or LPS; btr_scene_from_labels writes RAS)");
    const PatientFrame frame = *s.patient_frame;
    const auto prone_pts = c.load("landmarks.prone", [&] { return read_markups(c.path_of(lm["prone"], "landmarks.prone"), frame); });
    const auto supine_pts = c.load("landmarks.supine", [&] { return read_markups(c.path_of(lm["supine"], "landmarks.supine"), frame); });
    const MatchedPoints m = match_by_label(prone_pts, supine_pts);
    if (m.labels.empty()) c.fail("landmarks", "no label is in both point lists, so no landmark pair can be made");
    if (!m.unmatched.empty()) {
      std::string list;
      for (const auto& l : m.unmatched) list += (list.empty() ? "" : ", ") + l;
      s.warnings.push_back("landmarks: " + std::to_string(m.unmatched.size()) + " points in only one list, not used: " + list);
    }
    s.landmark_labels = m.labels;
    s.landmark_supine = m.second;
    if (s.prone_source) {
      s.prone_source->landmarks = m.first;
    } else {
      const BoundaryAttachment a = attach_to_boundary(s.prone, m.first);
      check_landmark_attachment(a, m.labels, path);
      s.landmark_anchors = a.anchors;
    }
  } else if (root["landmarks"]) {
    const auto pairs = c.load("landmarks", [&] { return read_landmark_pairs(c.path_of(root["landmarks"], "landmarks"), s.units); });
    Points prone_pts(pairs.size(), 3);
    s.landmark_supine.resize(pairs.size(), 3);
    for (size_t i = 0; i < pairs.size(); ++i) {
      const auto& p = pairs[i];
      const long n_prone = s.prone_source ? prone_surface.V.rows() : s.prone.V.rows();
      if (p.prone_vertex >= n_prone)
        c.fail("landmarks", "pair " + std::to_string(i) + ": prone vertex " + std::to_string(p.prone_vertex) +
                                " out of range (" + std::to_string(n_prone) + " vertices)");
      if (p.supine_vertex >= 0) {
        if (!s.supine_surface) c.fail("landmarks", "pair " + std::to_string(i) + " names a supine vertex but there is no supine.surface");
        if (p.supine_vertex >= s.supine_surface->V.rows())
          c.fail("landmarks", "pair " + std::to_string(i) + ": supine vertex " + std::to_string(p.supine_vertex) + " out of range");
        s.landmark_supine.row(i) = s.supine_surface->V.row(p.supine_vertex);
      } else {
        s.landmark_supine.row(i) = p.supine_point.transpose();
      }
      if (s.prone_source) prone_pts.row(i) = prone_surface.V.row(p.prone_vertex);
      else s.landmark_anchors.push_back(Anchor::vertex(p.prone_vertex));
    }
    if (s.prone_source) s.prone_source->landmarks = prone_pts;
    // The same pair given twice adds nothing but cost: merged, with a warning.
    std::vector<Eigen::Index> keep;
    for (Eigen::Index i = 0; i < s.landmark_supine.rows(); ++i) {
      bool dup = false;
      for (Eigen::Index j : keep)
        dup = dup || ((s.prone_source ? (prone_pts.row(i) - prone_pts.row(j)).norm() == 0
                                      : s.landmark_anchors[i].v[0] == s.landmark_anchors[j].v[0]) &&
                      (s.landmark_supine.row(i) - s.landmark_supine.row(j)).norm() == 0);
      if (!dup) keep.push_back(i);
    }
    if (keep.size() < static_cast<size_t>(s.landmark_supine.rows())) {
      s.warnings.push_back("landmarks: " + std::to_string(s.landmark_supine.rows() - static_cast<Eigen::Index>(keep.size())) +
                           " duplicate pairs merged");
      Points sup(keep.size(), 3), pro(keep.size(), 3);
      std::vector<Anchor> anchors;
      for (size_t k = 0; k < keep.size(); ++k) {
        sup.row(k) = s.landmark_supine.row(keep[k]);
        if (s.prone_source) pro.row(k) = prone_pts.row(keep[k]);
        else anchors.push_back(s.landmark_anchors[keep[k]]);
      }
      s.landmark_supine = sup;
      if (s.prone_source) s.prone_source->landmarks = pro;
      else s.landmark_anchors = anchors;
    }
  }

  // Tumours.
  if (root["tumours"]) {
    if (!root["tumours"].IsSequence()) c.fail("tumours", "expected a list of {name, prone, supine_ground_truth}");
    int i = 0;
    for (const auto& t : root["tumours"]) {
      const std::string f = "tumours[" + std::to_string(i++) + "]";
      SceneTumour st;
      if (!t.IsMap()) c.fail(f, "expected a mapping {name, prone, supine_ground_truth}");
      st.name = t["name"] ? c.text(t["name"], f + ".name") : "tumour" + std::to_string(i - 1);
      if (!t["prone"]) c.fail(f + ".prone", "missing tumour surface");
      st.prone = c.load(f + ".prone", [&] {
        SurfaceMesh m = read_surface(c.path_of(t["prone"], f + ".prone"), s.units);
        validate_surface(m, f + ".prone");
        return m;
      });
      if (t["supine_ground_truth"])  // checked and oriented at load: an inside-out truth gave a volume ratio of -1
        st.supine_ground_truth = c.load(f + ".supine_ground_truth", [&] {
          SurfaceMesh m = read_surface(c.path_of(t["supine_ground_truth"], f + ".supine_ground_truth"), s.units);
          repair_orientation(m, f + ".supine_ground_truth", s.warnings);
          validate_surface(m, f + ".supine_ground_truth");
          return m;
        });
      s.tumours.push_back(std::move(st));
    }
  }

  // Material, gravity, steps, preset.
  if (const YAML::Node m = root["material"]) {
    if (m["youngs_modulus"]) {
      if (m["youngs_modulus"].IsScalar() && m["youngs_modulus"].Scalar() == "estimate") {
        s.youngs_modulus_range = std::array<double, 2>{150, 24000};  // the reference stays 3400 Pa
      } else {
        s.material.youngs_modulus = c.number(m["youngs_modulus"], "material.youngs_modulus");
      }
    }
    if (m["youngs_modulus_range"]) {
      if (!s.youngs_modulus_range)
        c.fail("material.youngs_modulus_range", "only with 'youngs_modulus: estimate'");
      const YAML::Node r = m["youngs_modulus_range"];
      if (!r.IsSequence() || r.size() != 2) c.fail("material.youngs_modulus_range", "expected [min, max] in Pa");
      const double lo = c.number(r[0], "material.youngs_modulus_range"), hi = c.number(r[1], "material.youngs_modulus_range");
      if (!(lo > 0) || !(hi > 1.5 * lo))
        c.fail("material.youngs_modulus_range", "expected 0 < min < max / 1.5 [Pa]");
      s.youngs_modulus_range = std::array<double, 2>{lo, hi};
    }
    if (m["poisson_ratio"]) s.material.poisson_ratio = c.number(m["poisson_ratio"], "material.poisson_ratio");
    if (m["density"]) s.material.density = c.number(m["density"], "material.density");
    if (m["volume_form"])
      c.load("material.volume_form", [&] {
        s.material.volume_form = parse_volume_form(c.text(m["volume_form"], "material.volume_form"));
        return 0;
      });
    if (m["unload_element_order"])
      c.load("material.unload_element_order", [&] {
        s.material.unload_element_order = parse_element_order(c.text(m["unload_element_order"], "material.unload_element_order"));
        s.unload_element_order_stated = true;
        return 0;
      });
    if (m["nodal_fallback"]) s.nodal_fallback = c.boolean(m["nodal_fallback"], "material.nodal_fallback");
    if (m["nodal_element_share"]) {
      s.material.nodal_element_share = c.number(m["nodal_element_share"], "material.nodal_element_share");
      if (!(s.material.nodal_element_share >= 0) || !std::isfinite(s.material.nodal_element_share))
        c.fail("material.nodal_element_share", "must be >= 0 (in units of the shear modulus)");
    }
  }
  c.load("material", [&] { StableNeoHookean(s.material.youngs_modulus, s.material.poisson_ratio); return 0; });
  if (!(s.material.density > 0)) c.fail("material.density", "must be positive (kg/m^3)");
  // Material regions (material_regions.h): after the material, whose Poisson's ratio they share.
  if (const YAML::Node rs = root["regions"]) {
    if (!rs.IsSequence()) c.fail("regions", "expected a list of {name, youngs_modulus, label or surface}");
    bool by_label = false;
    int i = 0;
    for (const auto& r : rs) {
      const std::string f = "regions[" + std::to_string(i++) + "]";
      if (!r.IsMap()) c.fail(f, "expected a mapping {name, youngs_modulus, label or surface}");
      MaterialRegion mr;
      if (!r["name"]) c.fail(f + ".name", "missing: a region needs a name (e.g. gland)");
      mr.name = c.text(r["name"], f + ".name");
      if (r["youngs_modulus"].IsDefined() == r["relative_stiffness"].IsDefined())
        c.fail(f, "give exactly one of 'youngs_modulus' [Pa] and 'relative_stiffness' (times material.youngs_modulus)");
      if (r["youngs_modulus"]) {
        mr.youngs_modulus = c.number(r["youngs_modulus"], f + ".youngs_modulus");
      } else {
        const double k = c.number(r["relative_stiffness"], f + ".relative_stiffness");
        if (!(k > 0) || !std::isfinite(k)) c.fail(f + ".relative_stiffness", "must be a positive number");
        mr.youngs_modulus = k * s.material.youngs_modulus;
      }
      if (r["label"]) {
        mr.label = c.cell_label(r["label"], f + ".label");
        by_label = true;
      }
      if (r["surface"])
        mr.surface = c.load(f + ".surface", [&] {
          SurfaceMesh m = read_surface(c.path_of(r["surface"], f + ".surface"), s.units);
          repair_orientation(m, f + ".surface", s.warnings);
          return m;
        });
      c.load(f, [&] { validate_material_region(mr, "region"); return 0; });
      s.regions.push_back(std::move(mr));
    }
    if (by_label) {
      if (!prone["tet_mesh"]) c.fail("regions", "a region by label needs prone.tet_mesh with cell labels");
      const std::string array = prone["cell_labels"] ? c.text(prone["cell_labels"], "prone.cell_labels") : "";
      s.prone_labels = c.load("prone.tet_mesh", [&] { return cell_labels(prone_file, array, c.path_of(prone["tet_mesh"], "prone.tet_mesh")); });
    }
  }
  if (const YAML::Node m = root["tumour_material"]) {
    s.tumour_youngs_modulus = c.number(m["youngs_modulus"], "tumour_material.youngs_modulus");
    c.load("tumour_material", [&] { StableNeoHookean(*s.tumour_youngs_modulus, s.material.poisson_ratio); return 0; });
  }
  if (!root["gravity"])
    c.fail("gravity", "missing: the supine gravity in the prone model's frame [m/s^2], e.g. [0, 0, -9.81] when the "
                      "chest wall is the plane z = 0 and the breast points towards +z");
  s.gravity = c.vec3(root["gravity"], "gravity");
  if (!(s.gravity.norm() > 0)) c.fail("gravity", "must not be zero");
  if (root["prone_gravity"]) {
    s.prone_gravity = c.vec3(root["prone_gravity"], "prone_gravity");
    if (!(s.prone_gravity->norm() > 0)) c.fail("prone_gravity", "must not be zero");
  }
  if (const YAML::Node st = root["steps"]) {
    if (st.IsScalar() && c.text(st, "steps") == "auto") {
    } else if (st.IsSequence()) {
      for (const auto& n : st) {
        const std::string name = c.text(n, "steps");
        if (name != "rigid" && name != "unload" && name != "gravity" && name != "landmarks" && name != "surface")
          c.fail("steps", "unknown step '" + name + "' (rigid, unload, gravity, landmarks, surface)");
        s.steps.push_back(name);
      }
      if (s.steps.empty()) c.fail("steps", "empty list; use 'auto' or name the steps");
    } else {
      c.fail("steps", "expected 'auto' or a list of steps");
    }
  }
  if (const YAML::Node u = root["uncertainty"]) {  // uncertainty_sources.h: the defaults unless given
    if (!u.IsMap()) c.fail("uncertainty", "expected a mapping of the uncertain inputs' distributions");
    auto range = [&](const char* key, std::array<double, 2>& r) {
      const std::string f = std::string("uncertainty.") + key;
      if (!u[key]) return;
      if (!u[key].IsSequence() || u[key].size() != 2) c.fail(f, "expected [min, max] ([0, 0]: held)");
      r = {c.number(u[key][0], f), c.number(u[key][1], f)};
    };
    range("youngs_modulus_range", s.uncertainty.youngs_modulus_range);
    range("poisson_ratio_range", s.uncertainty.poisson_ratio_range);
    if (u["gravity_direction_deg"]) s.uncertainty.gravity_direction_deg = c.number(u["gravity_direction_deg"], "uncertainty.gravity_direction_deg");
    if (u["landmark_sd_mm"]) s.uncertainty.landmark_sd = 1e-3 * c.number(u["landmark_sd_mm"], "uncertainty.landmark_sd_mm");
    if (u["depth_noise_mm"]) s.uncertainty.depth_noise = 1e-3 * c.number(u["depth_noise_mm"], "uncertainty.depth_noise_mm");
    if (u["rigid_pose"]) s.uncertainty.rigid_pose = c.boolean(u["rigid_pose"], "uncertainty.rigid_pose");
    if (u["discretisation"]) s.uncertainty.discretisation = c.boolean(u["discretisation"], "uncertainty.discretisation");
    c.load("uncertainty", [&] { validate_uncertainty_sources(s.uncertainty); return 0; });
  }
  if (root["preset"]) s.preset = c.text(root["preset"], "preset");
  if (s.preset != "fast" && s.preset != "balanced" && s.preset != "accurate")
    c.fail("preset", "unknown preset '" + s.preset + "' (fast, balanced, accurate)");

  // Simulated misalignment of the supine data (experiments of thesis Sec. 5.2.5).
  if (const YAML::Node mis = root["misalignment"]) {
    Vec3 rot = Vec3::Zero(), tr = Vec3::Zero();
    if (mis["rotation_deg"]) rot = c.vec3(mis["rotation_deg"], "misalignment.rotation_deg");
    if (mis["translation_mm"]) tr = c.vec3(mis["translation_mm"], "misalignment.translation_mm");
    apply_misalignment(s, misalignment_from_degrees_mm(rot, tr));
  }
  return s;
}
}  // namespace

void repair_orientation(SurfaceMesh& m, const std::string& name, std::vector<std::string>& warnings) {
  SurfaceCheckOptions o;
  o.require_consistent_orientation = false;
  validate_surface(m, name, o);  // closed, manifold, indices in range: only the orientation is left to repair
  const long flipped = orient_closed_surface(m, name);
  if (flipped > 0)
    warnings.push_back(name + ": " + std::to_string(flipped) + " of " + std::to_string(m.F.rows()) +
                       " faces were oriented against their neighbours or inwards; repaired");
}

}  // namespace btr
