// The phantom truth's mesh convergence: how far its tumours move prone -> supine per cell size and
// element order (simulate_phantom). Usage: phantom_truth_convergence E CELL_MM [CELL_MM ...]
#include <cstdio>
#include <cstdlib>
#include <chrono>
#include "breast_tumour_registration/geometry/metrics.h"
#include "breast_tumour_registration/simulation/phantom_scene.h"
using namespace btr;
int main(int argc, char** argv) {
  const double E = std::atof(argv[1]);
  for (int a = 2; a < argc; ++a) {
    const double cell = std::atof(argv[a]);
    PhantomOptions po; po.tet.cell_size = cell * 1e-3;
    const PhantomModel m = make_phantom_model(po);
    for (ElementOrder o : {ElementOrder::Linear, ElementOrder::Quadratic}) {
      PhantomSceneOptions so; so.youngs_modulus = E; so.element_order = o;
      const auto t0 = std::chrono::steady_clock::now();
      try {
        const PhantomConfigurations c = simulate_phantom(m, so);
        double s = 0, mid = 0;
        for (const auto& [n, t] : c.tumour_prone) {
          const double d = (volume_centroid(c.tumour_supine.at(n)) - volume_centroid(t)).norm() * 1e3;
          s += d / 5; if (n == "middle") mid = d;
        }
        std::printf("E %.0f cell %.0f mm (%ld tets) %s: tumours move %.2f mm on average, middle %.2f mm; corner tets inverted prone %ld; %.1f s\n", E, cell,
                    (long)m.rest.T.rows(), to_string(o), s, mid, c.prone_corner_inversions,
                    std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
      } catch (const std::exception& e) { std::printf("E %.0f cell %.0f %s: %s\n", E, cell, to_string(o), e.what()); }
      std::fflush(stdout);
    }
  }
}
