// Probe: carry each stiff tumour by Eshelby's interior strain of a sphere in an incompressible
// matrix (strain inside = 5 / (3 r + 2) of the far field, r = mu_tumour / mu_matrix), the far
// field fitted to the mesh's vertices around it, instead of by the coarse mesh's own map.
#include <cstdio>
#include <map>
#include <Eigen/SVD>
#include "breast_tumour_registration/geometry/metrics.h"
#include "breast_tumour_registration/geometry/embedding.h"
#include "breast_tumour_registration/registration/registration_engine.h"
#include "breast_tumour_registration/io/scene.h"
using namespace btr;
int main(int argc, char** argv) {
  setvbuf(stdout, nullptr, _IONBF, 0);
  const std::string preset = argc > 2 ? argv[2] : "balanced";
  const double shell = argc > 3 ? std::atof(argv[3]) : 2.5;
  const int mode = argc > 4 ? std::atoi(argv[4]) : 1;
  RegistrationEngine engine(load_scene(argv[1]));
  const RegistrationOptions opt = preset_options(preset);
  const RegistrationResult r = engine.solve(opt);
  const PreparedScene& p = engine.prepared_for(opt, r);
  const RegistrationModel& m = p.model;
  for (size_t i = 0; i < m.tumours.size(); ++i) {
    const auto& tu = m.tumours[i];
    const TumourResult& tr = r.tumours[i];
    const Vec3 cp = volume_centroid(tu.prone);
    const double R = std::cbrt(3 * std::abs(enclosed_volume(tu.prone)) / (4 * M_PI));
    // far field: affine fit over the vertices within shell * R
    std::vector<int> near;
    for (Eigen::Index v = 0; v < m.prone.rows(); ++v)
      if ((m.prone.row(v).transpose() - cp).norm() < shell * R) near.push_back(static_cast<int>(v));
    auto fit = [&](const Points& from, const Points& to) {
      Eigen::MatrixXd A(near.size(), 4), B(near.size(), 3);
      Vec3 c0 = Vec3::Zero();
      for (int v : near) c0 += from.row(v).transpose() / near.size();
      for (size_t k = 0; k < near.size(); ++k) {
        A.row(k) << (from.row(near[k]).transpose() - c0).transpose(), 1.0;
        B.row(k) = to.row(near[k]);
      }
      const Eigen::MatrixXd sol = A.colPivHouseholderQr().solve(B);
      return Mat3(sol.topRows(3).transpose());
    };
    auto eshelby = [](const Mat3& G, double a) {
      Eigen::JacobiSVD<Mat3> svd(G, Eigen::ComputeFullU | Eigen::ComputeFullV);
      const Mat3 Rot = svd.matrixU() * svd.matrixV().transpose();
      const Mat3 U = svd.matrixV() * svd.singularValues().asDiagonal() * svd.matrixV().transpose();
      return Mat3(Rot * (Mat3::Identity() + a * (U - Mat3::Identity())));
    };
    const Mat3 Fp = fit(m.rest.V, m.prone), Fs = fit(m.rest.V, r.x), G = fit(m.prone, r.x);
    // tumour and matrix moduli: the tumour's region and the commonest other material around
    const Embedding& e = tu.embedding;
    std::map<int, int> inside_mat, around_mat;
    for (Eigen::Index k = 0; k < e.tet.size(); ++k) inside_mat[m.material_of[e.tet[k]]]++;
    for (Eigen::Index t = 0; t < m.rest.T.rows(); ++t) {
      Vec3 c = Vec3::Zero();
      for (int k = 0; k < 4; ++k) c += m.prone.row(m.rest.T(t, k)).transpose() / 4;
      const double d = (c - cp).norm();
      if (d > 1.2 * R && d < shell * R) around_mat[m.material_of[t]]++;
    }
    auto commonest = [](const std::map<int, int>& h) { int b = -1, n = -1; for (auto [k, c] : h) if (c > n) b = k, n = c; return b; };
    const int mt = commonest(around_mat);
    // the tumour's own region by name
    double Et = 0;
    for (size_t k = 0; k < m.material_names.size(); ++k)
      if (m.material_names[k] == "tumour_" + tu.name || m.material_names[k] == tu.name) Et = m.materials[k].youngs_modulus();
    const double Em = m.materials[mt].youngs_modulus();
    const double ratio = Et > 0 ? Et / Em : 1;
    const Vec3 creg = volume_centroid(tr.registered);  // supine frame; shape only matters
    for (double a : {1.0, 5 / (3 * ratio + 2)}) {
      const Mat3 Gin = mode == 0 ? eshelby(G, a) : Mat3(eshelby(Fs, a) * eshelby(Fp, a).inverse());
      SurfaceMesh s = tu.prone;
      for (Eigen::Index v = 0; v < s.V.rows(); ++v) s.V.row(v) = (Gin * (s.V.row(v).transpose() - cp)).transpose();
      std::printf("%s %-8s A=%.3f (r %.2f, Em %.0f) axis %.3f | registered %.3f prone %.3f truth %.3f | near %zu\n", argv[1] + std::string(argv[1]).rfind('/', std::string(argv[1]).rfind('/') - 1) + 1,
                  tu.name.c_str(), a, ratio, Em, principal_axis_ratio(s), tr.axis_ratio, tr.prone_axis_ratio, tr.truth_axis_ratio, near.size());
    }
  }
}
