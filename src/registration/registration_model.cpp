#include "breast_tumour_registration/registration/registration_model.h"

#include <algorithm>
#include <cmath>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/geometry/metrics.h"
#include "breast_tumour_registration/geometry/surface_attachment.h"
#include "breast_tumour_registration/geometry/validation.h"
#include "breast_tumour_registration/io/index_io.h"

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
  m.volume_form = resolve_volume_form(material.volume_form, material.poisson_ratio);
  if (!(material.density > 0) || !std::isfinite(material.density))
    throw InputError("material.density must be positive (kg/m^3)");
  m.material_of.assign(m.rest.T.rows(), 0);
  m.material_names = {"body"};
  m.material_tetrahedra = {static_cast<long>(m.rest.T.rows())};
  m.gravity = gravity;
  for (Eigen::Index t = 0; t < m.rest.T.rows(); ++t) m.volume += tet_signed_volume(m.rest.V, m.rest.T, t);
  m.prone = m.rest.V;
  return m;
}

int add_tumour(RegistrationModel& model, const std::string& name, const SurfaceMesh& tumour) {
  validate_surface(tumour, "tumour '" + name + "'");
  EmbeddedTumour t;
  t.name = name;
  t.prone = tumour;
  // Given on the prone image: embedded in the prone positions (the coordinates then hold for any).
  t.embedding = embed_points(TetMesh{model.prone, model.rest.T}, tumour.V, OutsidePolicy::NearestTetrahedron);
  const int outside = static_cast<int>(t.embedding.outside.size());
  model.tumours.push_back(std::move(t));
  return outside;
}


void add_model_elastic_energy(TotalEnergy& energy, const RegistrationModel& model) {
  add_elastic_energy(energy, model.rest, model.materials, model.material_of, model.volume_form,
                     model.material.nodal_element_share);
}

void stiffen_tumours(RegistrationModel& model, double E) {
  const int index = static_cast<int>(model.materials.size());
  model.materials.push_back(StableNeoHookean(E, model.material.poisson_ratio));
  model.material_names.push_back("tumour");
  model.material_tetrahedra.push_back(0);
  std::vector<const SurfaceMesh*> surfaces;
  for (const auto& t : model.tumours) surfaces.push_back(&t.prone);
  const std::vector<int> inside = tetrahedra_inside(TetMesh{model.prone, model.rest.T}, surfaces);
  for (int e : inside) model.material_of[e] = index;
  model.stiff_tetrahedra = static_cast<long>(inside.size());
  count_material_tetrahedra(model);
}

void count_material_tetrahedra(RegistrationModel& model) {
  model.material_tetrahedra.assign(model.materials.size(), 0);
  for (int m : model.material_of) ++model.material_tetrahedra[m];
}

}  // namespace btr
