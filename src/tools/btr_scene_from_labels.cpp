// btr_scene_from_labels: a segmented prone image (NIfTI or NRRD label map, e.g. from 3D Slicer)
// with its skin fiducials and a supine surface becomes a registration scene for btr_register.
#include <CLI/CLI.hpp>

#include "breast_tumour_registration/cli_checks.h"

#include <cstdio>
#include <filesystem>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/units.h"
#include "breast_tumour_registration/io/label_scene.h"
#include "breast_tumour_registration/io/label_volume_io.h"
#include "breast_tumour_registration/registration/registration_pipeline.h"

using namespace btr;

int main(int argc, char** argv) {
  CLI::App app{
      "Mesh a segmented prone breast image into a registration scene (multi-material tetrahedra with CGAL Mesh_3,\n"
      "chest wall from the muscle label, tumours as surfaces, regions per tissue) and write DIR/scene.yaml for\n"
      "btr_register. Label values follow the label table (--labels; defaults fat 1, gland 2, tumour 3, muscle 4)."};
  std::string label_map, table_path, out_dir = "label_scene", prone_lm, supine_lm, supine_surface, supine_cloud;
  std::string supine_units = "mm", preset = "balanced";
  double cell_mm = 7, tumour_facet_mm = 1.5, E = 3400, nu = 0.49;
  bool not_prone = false, no_features = false;
  std::vector<std::string> truth;
  app.add_option("label_map", label_map, "prone label map: .nii, .nii.gz, .nrrd, .nhdr or .seg.nrrd")->required();
  app.add_option("--labels", table_path, "label table (YAML): which label value or segment name is which tissue");
  app.add_option("-o,--out", out_dir, "scene folder (created)")->capture_default_str();
  auto* cell_opt = app.add_option("--cell-size", cell_mm,
                                  "tetrahedron size bound [mm]; default: the mesh the preset simulates, so it simulates this "
                                  "one as it is (a prone image, which is unloaded, with the nodal form: fast 11, balanced 9, "
                                  "accurate 7; --not-prone: 9, 7, 4)")
                       ->check(btr::cli::positive());
  app.add_option("--tumour-facet-size", tumour_facet_mm, "facet size bound on the tumours' surfaces [mm]")
      ->capture_default_str()
      ->check(btr::cli::positive());
  app.add_option("--prone-landmarks", prone_lm, "prone skin fiducials: Slicer .mrk.json or .fcsv (LPS or RAS, as the file says)");
  app.add_option("--supine-landmarks", supine_lm, "the same fiducials on the supine side, matched by label");
  app.add_option("--supine-surface", supine_surface, "supine surface scan (.obj .ply .stl .off), RAS");
  app.add_option("--supine-cloud", supine_cloud, "or a supine point cloud (.xyz .ply), RAS");
  app.add_option("--supine-units", supine_units, "length unit of the supine file: mm or m")->capture_default_str();
  app.add_option("-E,--youngs-modulus", E, "fat's Young's modulus [Pa]; the other tissues are relative to it")
      ->capture_default_str()
      ->check(btr::cli::positive());
  app.add_option("--poisson-ratio", nu, "Poisson's ratio")->capture_default_str();
  app.add_option("--preset", preset, "the scene's preset: fast, balanced, accurate")->capture_default_str();
  app.add_option("--truth", truth, "a known tumour as NAME,PRONE.obj,SUPINE.obj (RAS, mm), for validation; repeatable");
  app.add_flag("--not-prone", not_prone, "the image was not taken prone: no prone_gravity (the image shape is the rest shape)");
  app.add_flag("--no-features", no_features, "do not protect the lines where three labels meet");
  if (const int rc = btr::cli::parse(app, argc, argv); rc >= 0) return rc;
  try {
    // The mesh the preset simulates this scene on, so that the registration simulates it as it
    // is: a prone image is unloaded (prone_gravity), where the presets take their nodal form on
    // its own mesh (before, balanced re-meshed a 7 mm label mesh at 9 mm).
    if (!cell_opt->count()) {
      Scene written;  // as write_scene_from_labels writes it: volume form auto, prone_gravity for a prone image
      if (!not_prone) written.prone_gravity = Vec3(0, 0, -9.81);
      const double preset_cell = simulation_cell_size_for(written, preset_options(preset));
      cell_mm = preset_cell > 0 ? preset_cell * 1e3 : 7.0;
    }
    const LabelVolume v = read_label_volume(label_map);
    const LabelTable table = table_path.empty() ? LabelTable{} : read_label_table(table_path, v);
    LabelSceneOptions o;
    o.mesh.source = label_map;
    o.mesh.cell_size = mm_to_m(cell_mm);
    o.mesh.tumour_facet_size = tumour_facet_mm * 1e-3;
    o.mesh.protect_features = !no_features;
    o.prone_landmarks = prone_lm;
    o.supine_landmarks = supine_lm;
    o.supine_surface = supine_surface;
    o.supine_cloud = supine_cloud;
    o.supine_units = supine_units;
    o.prone_image = !not_prone;
    o.youngs_modulus = E;
    o.poisson_ratio = nu;
    o.preset = preset;
    for (const auto& t : truth) {
      const auto a = t.find(','), b = t.find(',', a == std::string::npos ? a : a + 1);
      if (a == std::string::npos || b == std::string::npos)
        throw InputError("--truth '" + t + "': expected NAME,PRONE.obj,SUPINE.obj");
      o.truth.push_back({t.substr(0, a), t.substr(a + 1, b - a - 1), t.substr(b + 1)});
    }
    const Vec3 sp = v.spacing() * 1e3;
    std::printf("[labels] %s: %d x %d x %d voxels of %.2f x %.2f x %.2f mm\n", label_map.c_str(), v.nx, v.ny, v.nz, sp[0], sp[1],
                sp[2]);
    const LabelSceneSummary s = write_scene_from_labels(out_dir, v, table, o);
    std::printf("[labels] %ld tetrahedra, %ld vertices, %ld chest-wall vertices (%s) in %.2f s\n", s.tetrahedra, s.vertices,
                s.chest_wall_vertices, s.chest_wall_from_muscle ? "interface with the muscle" : "posterior-most skin",
                s.mesh_seconds);
    for (const auto& [name, c] : s.tumour_centroids)
      std::printf("[labels] %s: centroid (%.1f, %.1f, %.1f) mm RAS\n", name.c_str(), c[0] * 1e3, c[1] * 1e3, c[2] * 1e3);
    for (const auto& w : s.warnings) std::printf("[labels] warning: %s\n", w.c_str());
    std::printf("[labels] wrote %s\n", (std::filesystem::path(out_dir) / "scene.yaml").string().c_str());
    return 0;
  } catch (const InputError& e) {
    std::fprintf(stderr, "btr_scene_from_labels: invalid input: %s\n", e.what());
    return 2;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "btr_scene_from_labels: error: %s\n", e.what());
    return 1;
  }
}
