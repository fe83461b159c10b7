#include "breast_tumour_registration/core/registration_model.h"

#include <algorithm>
#include <cmath>

#include "breast_tumour_registration/core/errors.h"
#include "breast_tumour_registration/core/index_io.h"
#include "breast_tumour_registration/core/metrics.h"
#include "breast_tumour_registration/core/surface_attachment.h"
#include "breast_tumour_registration/core/validation.h"

namespace btr {

RegistrationModel make_registration_model(const TetMesh& prone, const std::vector<int>& chest_wall,
                                          const MaterialParameters& material, const Vec3& gravity) {
  RegistrationModel m;
  m.rest = prone;
  orient_tets_positive(m.rest);
  validate_tet_mesh(m.rest, "prone tetrahedral mesh");
  check_index_range(chest_wall, m.rest.V.rows(), "chest wall");
  if (chest_wall.size() < 3) throw InputError("chest wall: at least 3 fixed vertices are needed, got " + std::to_string(chest_wall.size()));
  if (!gravity.allFinite()) throw InputError("gravity: vector is not finite");
  m.chest_wall = chest_wall;
  m.fixed.assign(m.rest.V.rows(), false);
  for (int v : chest_wall) m.fixed[v] = true;
  for (int v : boundary_vertices(m.rest))
    if (!m.fixed[v]) m.skin.push_back(v);
  if (m.skin.empty()) throw InputError("chest wall: every boundary vertex is fixed, no skin is left to register");
  m.material = material;
  m.materials = {StableNeoHookean(material.youngs_modulus, material.poisson_ratio)};
  if (!(material.density > 0) || !std::isfinite(material.density))
    throw InputError("material.density must be positive (kg/m^3)");
  m.material_of.assign(m.rest.T.rows(), 0);
  m.gravity = gravity;
  for (Eigen::Index t = 0; t < m.rest.T.rows(); ++t) m.volume += tet_signed_volume(m.rest.V, m.rest.T, t);
  return m;
}

int add_tumour(RegistrationModel& model, const std::string& name, const SurfaceMesh& tumour) {
  validate_surface(tumour, "tumour '" + name + "'");
  EmbeddedTumour t;
  t.name = name;
  t.prone = tumour;
  t.embedding = embed_points(model.rest, tumour.V, OutsidePolicy::NearestTetrahedron);
  const int outside = static_cast<int>(t.embedding.outside.size());
  model.tumours.push_back(std::move(t));
  return outside;
}

namespace {
// Inside test by the winding number of a closed surface (robust to its sampling).
bool inside(const SurfaceMesh& s, const Vec3& p) {
  double w = 0;
  for (Eigen::Index f = 0; f < s.F.rows(); ++f) {
    const Vec3 a = Vec3(s.V.row(s.F(f, 0))) - p, b = Vec3(s.V.row(s.F(f, 1))) - p, c = Vec3(s.V.row(s.F(f, 2))) - p;
    const double la = a.norm(), lb = b.norm(), lc = c.norm();
    w += 2 * std::atan2(a.dot(b.cross(c)), la * lb * lc + a.dot(b) * lc + b.dot(c) * la + c.dot(a) * lb);
  }
  return w / (4 * M_PI) > 0.5;
}
}  // namespace

void stiffen_tumours(RegistrationModel& model, double E) {
  model.materials.erase(model.materials.begin() + 1, model.materials.end());
  model.materials.push_back(StableNeoHookean(E, model.material.poisson_ratio));
  std::fill(model.material_of.begin(), model.material_of.end(), 0);
  model.stiff_tetrahedra = 0;
  for (const auto& t : model.tumours) {
    const Vec3 lo = t.prone.V.colwise().minCoeff().transpose(), hi = t.prone.V.colwise().maxCoeff().transpose();
    for (Eigen::Index e = 0; e < model.rest.T.rows(); ++e) {
      Vec3 c = Vec3::Zero();
      for (int k = 0; k < 4; ++k) c += model.rest.V.row(model.rest.T(e, k)).transpose() / 4.0;
      if ((c.array() < lo.array()).any() || (c.array() > hi.array()).any()) continue;
      if (model.material_of[e] == 0 && inside(t.prone, c)) {
        model.material_of[e] = 1;
        ++model.stiff_tetrahedra;
      }
    }
  }
}

}  // namespace btr
