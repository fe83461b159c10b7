// Where the balanced preset's nodal form (9 mm) does not converge, which element model does the
// fallback give: the element form on the nodal form's 9 mm mesh (before 2026-12-06, eighth
// session) or on the preset's own element mesh (7 mm, the call without the preset's nodal form).
// Prints the worst tumour error of each, and what the engine's default call returns.
// Build against the package's libraries (after scripts/setup.sh):
//   L=build/ws/devel/lib; g++ -std=c++17 -O2 -Iinclude -I/usr/include/eigen3 bench/probes/fallback_mesh.cpp \
//     -o /tmp/fallback_mesh -L$L -lbtr_simulation -lbtr_registration -lbtr_io -lbtr_geometry -lbtr_fem -lbtr_base \
//     -Wl,-rpath,$PWD/$L
//   /tmp/fallback_mesh SCENE.yaml [tilt_deg shift_mm [steps]]   # steps e.g. landmarks,surface
#include <algorithm>
#include <cstdio>
#include <cstdlib>
#include <sstream>

#include "breast_tumour_registration/io/scene.h"
#include "breast_tumour_registration/registration/registration_engine.h"
#include "breast_tumour_registration/simulation/phantom_scene.h"
using namespace btr;

namespace {
double worst_mm(const RegistrationResult& r) {
  double w = 0;
  for (const auto& t : r.tumours) w = std::max(w, t.centroid_distance);
  return w * 1e3;
}
void print(const char* what, const RegistrationResult& r) {
  std::printf("%-34s worst %.3f mm, %6ld vertices, E %.0f Pa, %6.2f s, %s, %s form%s%s\n", what, worst_mm(r),
              static_cast<long>(r.x.rows()), r.estimated_youngs_modulus, r.seconds,
              r.converged ? "converged" : "NOT converged", to_string(r.volume_form),
              r.volume_form_fallback ? ", fell back: " : "",
              r.volume_form_fallback ? (r.volume_form_fallback->mesh_note.empty() ? "same mesh" : r.volume_form_fallback->mesh_note.c_str()) : "");
}
}  // namespace

int main(int argc, char** argv) {
  if (argc < 2) return 2;
  Scene s = load_scene(argv[1]);
  if (argc > 3) {
    const double deg = std::atof(argv[2]), mm = std::atof(argv[3]);
    if (deg != 0 || mm != 0) {
      apply_misalignment(s, misalignment_from_degrees_mm(Vec3(deg, 0, 0), Vec3(0, 0, mm)));
    }
  }
  if (argc > 4) {
    s.steps.clear();
    std::stringstream ss(argv[4]);
    for (std::string x; std::getline(ss, x, ',');) s.steps.push_back(x);
  }
  const RegistrationOptions balanced = preset_options("balanced");
  Scene kept = s;
  kept.nodal_fallback = false;
  print("nodal, 9 mm (no fallback)", RegistrationEngine(kept).solve(balanced));
  Scene element = s;
  element.material.volume_form = VolumeForm::Element;
  RegistrationOptions at9 = balanced;
  at9.simulation_cell_size = balanced.nodal_simulation_cell_size;
  print("element, 9 mm (the old fallback)", RegistrationEngine(element).solve(at9));
  print("element, 7 mm (the new fallback)", RegistrationEngine(element).solve(balanced));
  print("balanced as it runs", RegistrationEngine(s).solve(balanced));
}
