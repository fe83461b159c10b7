// What the supine mesh denoising (geometry/surface_denoising.h) does to a scan: a noise-free
// surface's noise estimate and how far the filter moves it when told of noise it does not have,
// and, for per-vertex noise along the normals (sd given, seeds 1 to 5), the estimate and the RMS
// distance to the noise-free vertices before and after (whole surface, and the crease: vertices
// whose noise-free normal and a face neighbour's differ by more than 45 degrees), and the time.
//   L=build/ws/devel/lib; g++ -std=c++17 -O2 -Iinclude -I/usr/include/eigen3 bench/probes/denoise_quality.cpp
//     -o /tmp/denoise_quality -L$L -lbtr_simulation -lbtr_registration -lbtr_io -lbtr_geometry -lbtr_fem -lbtr_base -Wl,-rpath,$PWD/$L
//   /tmp/denoise_quality test/data/independent_truth_E1000/supine.obj 0.5 1 2
#include <chrono>
#include <cmath>
#include <cstdio>
#include <random>
#include <string>
#include <vector>

#include "breast_tumour_registration/geometry/surface_denoising.h"
#include "breast_tumour_registration/geometry/vertex_normals.h"
#include "breast_tumour_registration/io/mesh_io.h"

using namespace btr;

int main(int argc, char** argv) {
  if (argc < 2) {
    std::fprintf(stderr, "usage: %s SURFACE.obj [noise sd mm ...]\n", argv[0]);
    return 2;
  }
  const SurfaceMesh clean = read_surface(argv[1], LengthUnit::Millimetre);
  const Points n = vertex_normals(clean);
  std::vector<char> crease(static_cast<size_t>(clean.V.rows()), 0);
  for (Eigen::Index f = 0; f < clean.F.rows(); ++f)
    for (int a = 0; a < 3; ++a)
      for (int b = 0; b < 3; ++b)
        if (n.row(clean.F(f, a)).dot(n.row(clean.F(f, b))) < std::cos(M_PI / 4)) crease[static_cast<size_t>(clean.F(f, a))] = 1;
  auto rms = [&](const SurfaceMesh& s, bool crease_only) {
    double sum = 0;
    long k = 0;
    for (Eigen::Index v = 0; v < s.V.rows(); ++v)
      if (!crease_only || crease[static_cast<size_t>(v)]) {
        sum += (s.V.row(v) - clean.V.row(v)).squaredNorm();
        ++k;
      }
    return k ? 1e3 * std::sqrt(sum / static_cast<double>(k)) : NAN;
  };
  const auto t0 = std::chrono::steady_clock::now();
  const double est0 = estimate_surface_noise(clean);
  const auto t1 = std::chrono::steady_clock::now();
  const SurfaceMesh moved = denoise_surface(clean, 0.25e-3);
  const auto t2 = std::chrono::steady_clock::now();
  std::printf("time: estimate %.1f ms, filter %.1f ms (one run)\n", 1e3 * std::chrono::duration<double>(t1 - t0).count(),
              1e3 * std::chrono::duration<double>(t2 - t1).count());
  long nc = 0;
  for (char c : crease) nc += c;
  std::printf("%s: %ld vertices (%ld at the crease); noise-free: estimate %.3f mm; filtered as if 0.25 mm noisy: moved %.3f mm RMS "
              "(crease %.3f)\n", argv[1], static_cast<long>(clean.V.rows()), nc, 1e3 * est0, rms(moved, false), rms(moved, true));
  for (int i = 2; i < argc; ++i) {
    const double sd = std::stod(argv[i]) * 1e-3;
    for (unsigned seed = 1; seed <= 5; ++seed) {
      std::mt19937 rng(seed);
      std::normal_distribution<double> g;
      SurfaceMesh noisy = clean;
      displace_along_normals(noisy, sd, [&] { return g(rng); });
      const double est = estimate_surface_noise(noisy);
      const SurfaceMesh d = denoise_surface(noisy, est);
      std::printf("  sd %.2f mm seed %u: estimate %.3f mm; RMS to the noise-free %.3f -> %.3f mm (crease %.3f -> %.3f)\n", sd * 1e3, seed,
                  1e3 * est, rms(noisy, false), rms(d, false), rms(noisy, true), rms(d, true));
    }
  }
}
