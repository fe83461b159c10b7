// btr_phantom: generates the thesis's synthetic breast phantom (Sec. 5.2.1) with its prone
// and supine configurations under gravity, and writes a scene that later steps can load.
#include <CLI/CLI.hpp>
#include <yaml-cpp/yaml.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <iostream>

#include "breast_tumour_registration/core/embedding.h"
#include "breast_tumour_registration/core/errors.h"
#include "breast_tumour_registration/core/gravity_simulation.h"
#include "breast_tumour_registration/core/index_io.h"
#include "breast_tumour_registration/core/mesh_io.h"
#include "breast_tumour_registration/core/phantom.h"
#include "breast_tumour_registration/core/surface_attachment.h"

namespace fs = std::filesystem;
using namespace btr;

namespace {

Vec3 centroid_of(const SurfaceMesh& s) {
  // Volume centroid of a closed surface (divergence theorem), robust to uneven sampling.
  double vol = 0;
  Vec3 c = Vec3::Zero();
  for (Eigen::Index f = 0; f < s.F.rows(); ++f) {
    const Vec3 a = s.V.row(s.F(f, 0)), b = s.V.row(s.F(f, 1)), d = s.V.row(s.F(f, 2));
    const double v = a.dot(b.cross(d)) / 6.0;
    vol += v;
    c += v * (a + b + d) / 4.0;
  }
  return c / vol;
}

}  // namespace

int main(int argc, char** argv) {
  CLI::App app{
      "Generate the synthetic breast phantom of the thesis (half ellipsoid 72 x 149 x 149 mm, fixed chest wall,\n"
      "five spherical tumours, landmark sets) and its prone and supine configurations under gravity.\n"
      "Writes a scene folder with tetrahedral meshes (VTK), surfaces (OBJ), tumours, landmarks and scene.yaml."};
  std::string out_dir = "phantom_scene";
  double E = 3400, nu = 0.49, rho = 1000, cell_mm = 8.0, tumour_mm = 10.0, ratio = 2.0;
  std::string units = "mm", landmark_set = "C+O";
  bool quiet = false;
  app.add_option("-o,--out", out_dir, "output folder (created)")->capture_default_str();
  app.add_option("-E,--youngs-modulus", E, "Young's modulus used to generate prone and supine [Pa]")->capture_default_str();
  app.add_option("--poisson-ratio", nu, "Poisson's ratio, in [0, 0.5)")->capture_default_str();
  app.add_option("--density", rho, "density [kg/m^3]")->capture_default_str();
  app.add_option("--cell-size", cell_mm, "tetrahedron size bound [mm] (8: ~6k tets, 4: ~35k)")->capture_default_str();
  app.add_option("--radius-edge-ratio", ratio, "tetrahedron quality bound (circumradius / shortest edge)")->capture_default_str();
  app.add_option("--tumour-radius", tumour_mm, "tumour sphere radius [mm]")->capture_default_str();
  app.add_option("--units", units, "length unit of the written files: mm or m")->capture_default_str();
  app.add_option("--landmarks", landmark_set, "landmark set: C+O, O+Oa+I, O+I, O+Oa, Oa+I, or names like C,O1,O2")
      ->capture_default_str();
  app.add_flag("-q,--quiet", quiet, "no per-iteration progress");
  CLI11_PARSE(app, argc, argv);

  const auto t0 = std::chrono::steady_clock::now();
  try {
    const LengthUnit unit = parse_length_unit(units);
    const auto landmark_names = phantom_landmark_set(landmark_set);
    PhantomOptions po;
    po.tet.cell_size = cell_mm * 1e-3;
    po.tet.radius_edge_ratio = ratio;
    po.tumour_radius = tumour_mm * 1e-3;
    StableNeoHookean(E, nu);  // validates E and nu before the expensive steps

    fs::create_directories(out_dir);
    std::printf("[phantom] tetrahedralizing the half ellipsoid (cell size %.2f mm)...\n", cell_mm);
    const PhantomModel model = make_phantom_model(po);
    const TetQuality q = tet_quality(model.rest);
    std::printf("[phantom] %ld vertices, %ld tetrahedra, %zu chest-wall vertices; radius-edge ratio median %.2f max %.2f, "
                "min dihedral %.1f deg\n",
                static_cast<long>(model.rest.V.rows()), static_cast<long>(model.rest.T.rows()), model.chest_wall.size(),
                q.median_radius_edge, q.max_radius_edge, q.min_dihedral_deg);

    NewtonOptions newton;
    auto solve = [&](const char* name, const Vec3& g) {
      GravityProblem pb;
      pb.rest = &model.rest;
      pb.fixed = model.chest_wall;
      pb.youngs_modulus = E;
      pb.poisson_ratio = nu;
      pb.density = rho;
      pb.gravity = g;
      newton.callback = [&](const IterationInfo& it) {
        if (!quiet)
          std::printf("[%s] iter %2d  energy %+.6e J  |grad| %.3e N  step %.3f mm (alpha %.3g)  %.2f s\n", name,
                      it.iteration, it.energy, it.gradient_norm, it.step_norm * 1e3, it.alpha, it.elapsed);
        return true;
      };
      GravityResult r = solve_gravity(pb, newton);
      std::printf("[%s] %s after %d iterations, %.2f s (assembly %.2f, factorization %.2f, solve %.2f, line search %.2f)\n",
                  name, to_string(r.newton.reason).c_str(), r.newton.iterations, r.newton.seconds, r.newton.t_assembly,
                  r.newton.t_factorization, r.newton.t_solve, r.newton.t_line_search);
      if (!r.newton.converged) throw SolverError(std::string(name) + " solve did not converge: " + to_string(r.newton.reason));
      return r.x;
    };
    const Points prone = solve("prone", Vec3(0, 0, 9.81));
    const Points supine = solve("supine", Vec3(0, 0, -9.81));

    auto path = [&](const std::string& f) { return (fs::path(out_dir) / f).string(); };
    write_surface(path("rest_surface.obj"), model.surface, unit);
    write_tet_mesh(path("rest.vtk"), model.rest, unit);
    write_index_list(path("chest_wall.txt"), model.chest_wall);
    write_surface(path("chest_ring.obj"), model.chest_ring, unit);
    TetMesh m = model.rest;
    m.V = prone;
    write_tet_mesh(path("prone.vtk"), m, unit);
    write_surface(path("prone_surface.obj"), boundary_surface(m), unit);
    m.V = supine;
    write_tet_mesh(path("supine.vtk"), m, unit);
    write_surface(path("supine_surface.obj"), boundary_surface(m), unit);

    std::vector<LandmarkPair> pairs;
    YAML::Node lm_vertices;
    for (const auto& [name, v] : model.landmarks) lm_vertices[name] = v;
    for (const auto& name : landmark_names) {
      LandmarkPair p;
      p.prone_vertex = model.landmarks.at(name);
      p.supine_point = supine.row(p.prone_vertex).transpose();
      pairs.push_back(p);
    }
    write_landmark_pairs(path("landmarks.csv"), pairs, unit);

    YAML::Node tumours;
    std::printf("[phantom] tumour centroids (prone -> supine displacement):\n");
    for (const auto& name : phantom_tumour_names()) {
      const SurfaceMesh& t = model.tumours.at(name);
      const Embedding emb = embed_points(model.rest, t.V, OutsidePolicy::Error);
      SurfaceMesh tp{apply_embedding(emb, model.rest.T, prone), t.F};
      SurfaceMesh ts{apply_embedding(emb, model.rest.T, supine), t.F};
      write_surface(path("tumour_" + name + "_rest.obj"), t, unit);
      write_surface(path("tumour_" + name + "_prone.obj"), tp, unit);
      write_surface(path("tumour_" + name + "_supine.obj"), ts, unit);
      YAML::Node n;
      n["name"] = name;
      n["rest"] = "tumour_" + name + "_rest.obj";
      n["prone"] = "tumour_" + name + "_prone.obj";
      n["supine_ground_truth"] = "tumour_" + name + "_supine.obj";
      tumours.push_back(n);
      std::printf("  %-7s %.1f mm\n", name.c_str(), (centroid_of(ts) - centroid_of(tp)).norm() * 1e3);
    }

    YAML::Emitter y;
    YAML::Node scene;
    scene["units"] = to_string(unit);
    scene["frame"] = "chest wall in z = 0, breast towards +z; prone gravity +z, supine gravity -z";
    scene["prone"]["tet_mesh"] = "prone.vtk";
    scene["prone"]["surface"] = "prone_surface.obj";
    scene["rest"]["tet_mesh"] = "rest.vtk";
    scene["rest"]["surface"] = "rest_surface.obj";
    scene["chest_wall"] = "chest_wall.txt";
    scene["chest_ring"] = "chest_ring.obj";
    scene["supine"]["surface"] = "supine_surface.obj";
    scene["supine"]["chest_ring"] = "chest_ring.obj";
    scene["supine"]["tet_mesh_ground_truth"] = "supine.vtk";
    scene["landmarks"] = "landmarks.csv";
    scene["landmark_set"] = landmark_set;
    scene["landmark_vertices"] = lm_vertices;
    scene["tumours"] = tumours;
    scene["material"]["youngs_modulus"] = 3400.0;
    scene["material"]["poisson_ratio"] = 0.49;
    scene["material"]["density"] = 1000.0;
    scene["gravity"] = std::vector<double>{0.0, 0.0, -9.81};
    scene["generator"]["youngs_modulus"] = E;
    scene["generator"]["poisson_ratio"] = nu;
    scene["generator"]["density"] = rho;
    scene["generator"]["cell_size_mm"] = cell_mm;
    scene["generator"]["tetrahedra"] = static_cast<long>(model.rest.T.rows());
    y << scene;
    std::ofstream(path("scene.yaml")) << "# Synthetic breast phantom written by btr_phantom\n" << y.c_str() << "\n";

    const double secs = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
    std::printf("[phantom] wrote scene to %s (scene.yaml, rest/prone/supine .vtk and surfaces, 15 tumour OBJs, "
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
