// btr_phantom: generates the thesis's synthetic breast phantom (Sec. 5.2.1) with its prone
// and supine configurations under gravity, and writes a scene that later steps can load.
#include <CLI/CLI.hpp>

#include "breast_tumour_registration/cli_checks.h"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/units.h"
#include "breast_tumour_registration/simulation/label_phantom.h"
#include "breast_tumour_registration/simulation/phantom_scene.h"

namespace fs = std::filesystem;
using namespace btr;


int main(int argc, char** argv) {
  CLI::App app{
      "Generate the synthetic breast phantom of the thesis (half ellipsoid 72 x 149 x 149 mm, fixed chest wall,\n"
      "five spherical tumours, landmark sets) and its prone and supine configurations under gravity.\n"
      "Writes a scene folder with tetrahedral meshes (VTK), surfaces (OBJ), tumours, landmarks and scene.yaml."};
  std::string out_dir = "phantom_scene";
  double E = 3400, nu = 0.49, rho = 1000, cell_mm = 8.0, tumour_mm = 10.0, ratio = 2.0;
  std::string units = "mm", landmark_set = "C+O";
  bool quiet = false;
  double tumour_E = 0, gland_E = 0;
  app.add_option("-o,--out", out_dir, "output folder (created)")->capture_default_str();
  app.add_option("-E,--youngs-modulus", E, "Young's modulus used to generate prone and supine [Pa]")->capture_default_str()
      ->check(btr::cli::positive());
  app.add_option("--poisson-ratio", nu, "Poisson's ratio, in [0, 0.5)")->capture_default_str();
  app.add_option("--density", rho, "density [kg/m^3]")->capture_default_str()->check(btr::cli::positive());
  app.add_option("--cell-size", cell_mm, "tetrahedron size bound [mm] (8: ~6k tets, 4: ~35k)")->capture_default_str()
      ->check(btr::cli::positive());
  app.add_option("--radius-edge-ratio", ratio, "tetrahedron quality bound (circumradius / shortest edge)")->capture_default_str();
  app.add_option("--tumour-radius", tumour_mm, "tumour sphere radius [mm]")->capture_default_str();
  app.add_option("--units", units, "length unit of the written files: mm or m")->capture_default_str();
  app.add_option("--landmarks", landmark_set, "landmark set: C+O, O+Oa+I, O+I, O+Oa, Oa+I, or names like C,O1,O2")
      ->capture_default_str();
  app.add_option("--tumour-youngs-modulus", tumour_E, "generate with stiff tumours of this Young's modulus [Pa] (0: homogeneous)")
      ->capture_default_str()
      ->check(btr::cli::non_negative());
  app.add_option("--gland-youngs-modulus", gland_E, "generate with a fibroglandular region of this Young's modulus [Pa] "
                                                    "(0: the body's); with either, prone.vtk carries tissue labels and the "
                                                    "scene their regions")
      ->capture_default_str()
      ->check(btr::cli::non_negative());
  ElementOrder element_order = ElementOrder::Linear;
  btr::cli::element_order_option(app, "--element-order", element_order,
                                 "the generating elements: linear (the registration's own kind) or quadratic (10-node "
                                 "tetrahedra on the same mesh, a truth nearer the converged answer; --volume-form does "
                                 "not apply; where the straight tetrahedra between their corners invert prone, the scene "
                                 "gives the prone model as its skin surface)");
  std::string volume_form = "auto";
  app.add_option("--volume-form", volume_form, "volume term of the generating material: auto, element or nodal "
                                               "(auto: nodal from nu = 0.495 up; README.md, \"Material\")")
      ->capture_default_str();
  double nodal_element_share = 0;
  app.add_option("--nodal-element-share", nodal_element_share,
                 "with the nodal volume term: the volume stiffness each tetrahedron keeps on its own volume change, "
                 "in units of its shear modulus (material.nodal_element_share)")
      ->capture_default_str()
      ->check(btr::cli::non_negative());
  std::string label_dir;
  std::vector<double> voxel_mm = {1.0};
  std::vector<int> min_voxels;
  app.add_option("--label-map", label_dir, "also write the prone phantom as a segmented image into this folder (RAS NIfTI label "
                                           "map: fat 1, gland 2, tumour 3, muscle 4; fiducials as Slicer .mrk.json in LPS; "
                                           "supine surface and tumour truth in RAS), for btr_scene_from_labels");
  app.add_option("--voxel-size", voxel_mm, "voxel size of --label-map [mm]: one value, or three (RAS x, y, z)")
      ->capture_default_str()
      ->expected(1, 3)
      ->delimiter(',')
      ->check(btr::cli::positive());
  app.add_option("--label-map-voxels", min_voxels, "grow the label map with air to at least NX,NY,NZ voxels (an MRI field of view)")
      ->expected(3)
      ->delimiter(',')
      ->check(CLI::NonNegativeNumber);
  app.add_flag("-q,--quiet", quiet, "no per-iteration progress");
  if (const int rc = btr::cli::parse(app, argc, argv); rc >= 0) return rc;

  const auto t0 = std::chrono::steady_clock::now();
  try {
    PhantomSceneOptions o;
    o.units = parse_length_unit(units);
    o.landmark_set = landmark_set;
    o.youngs_modulus = E;
    o.poisson_ratio = nu;
    o.volume_form = parse_volume_form(volume_form);
    o.element_order = element_order;
    o.nodal_element_share = nodal_element_share;
    o.density = rho;
    o.phantom.tet.cell_size = mm_to_m(cell_mm);
    o.phantom.tet.radius_edge_ratio = ratio;
    o.phantom.tumour_radius = tumour_mm * 1e-3;
    o.tumour_youngs_modulus = tumour_E;
    o.gland_youngs_modulus = gland_E;
    std::printf("[phantom] tetrahedralizing the half ellipsoid (cell size %.2f mm) and solving prone and supine...\n", cell_mm);
    const auto progress = [&](const std::string& name, const IterationInfo& it) {
      if (!quiet)
        std::printf("[%s] iter %2d  energy %+.6e J  |grad| %.3e N  step %.3f mm (alpha %.3g)  %.2f s\n", name.c_str(),
                    it.iteration, it.energy, it.gradient_norm, it.step_norm * 1e3, it.alpha, it.elapsed);
      return true;
    };
    const PhantomSceneSummary s = write_phantom_scene(out_dir, o, progress);
    std::printf("[phantom] %ld vertices, %ld tetrahedra, %ld chest-wall vertices; radius-edge ratio median %.2f max %.2f, "
                "min dihedral %.1f deg\n",
                s.vertices, s.tetrahedra, s.chest_wall_vertices, s.quality.median_radius_edge, s.quality.max_radius_edge,
                s.quality.min_dihedral_deg);
    for (const auto* r : {&s.prone, &s.supine})
      std::printf("[%s] %s after %d iterations, %.2f s (assembly %.2f, factorization %.2f, solve %.2f, line search %.2f)\n",
                  r == &s.prone ? "prone" : "supine", to_string(r->reason).c_str(), r->iterations, r->seconds,
                  r->t_assembly, r->t_factorization, r->t_solve, r->t_line_search);
    std::printf("[phantom] tumour centroids, prone -> supine displacement:");
    for (const auto& [name, d] : s.tumour_displacement) std::printf(" %s %.1f mm", name.c_str(), d * 1e3);
    if (!label_dir.empty()) {
      LabelPhantomOptions lo;
      if (voxel_mm.size() == 2) throw InputError("--voxel-size: give one value or three");
      lo.voxel_size = voxel_mm.size() == 3 ? Vec3(Vec3(voxel_mm[0], voxel_mm[1], voxel_mm[2]) * 1e-3) : Vec3(Vec3::Constant(voxel_mm[0] * 1e-3));
      if (min_voxels.size() == 3) lo.min_voxels = Eigen::Vector3i(min_voxels[0], min_voxels[1], min_voxels[2]);
      const LabelPhantomFiles f = write_label_phantom((fs::path(out_dir) / "scene.yaml").string(), label_dir, lo);
      std::printf("[phantom] label map %s: %d x %d x %d voxels of %.2f x %.2f x %.2f mm\n", f.label_map.c_str(), f.volume.nx,
                  f.volume.ny, f.volume.nz, lo.voxel_size.x() * 1e3, lo.voxel_size.y() * 1e3, lo.voxel_size.z() * 1e3);
    }
    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    if (s.prone_written_as_surface)
      std::printf("\n[phantom] the straight tetrahedra between the quadratic elements' corners invert prone, so the scene gives "
                  "the prone model as its skin (prone_surface.obj, meshed at %.2f mm by the method; chest wall and landmarks "
                  "numbered on it, regions as closed surfaces) and no prone.vtk",
                  cell_mm);
    std::printf("\n[phantom] wrote scene to %s (scene.yaml, rest/prone/supine meshes and surfaces, 15 tumour OBJs, "
                "landmarks.csv, chest_wall.txt, chest_ring.obj) in %.1f s\n",
                fs::absolute(out_dir).string().c_str(), secs);
    return 0;
  } catch (const InputError& e) {
    std::fprintf(stderr, "btr_phantom: invalid input: %s\n", e.what());
    return 2;
  } catch (const SolverError& e) {
    std::fprintf(stderr, "btr_phantom: solver failure: %s\n", e.what());
    return 3;
  } catch (const std::exception& e) {
    std::fprintf(stderr, "btr_phantom: error: %s\n", e.what());
    return 1;
  }
}
