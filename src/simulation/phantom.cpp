#include "breast_tumour_registration/simulation/phantom.h"

#include <algorithm>
#include <cmath>
#include <sstream>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/geometry/shapes.h"
#include "breast_tumour_registration/geometry/surface_attachment.h"

namespace btr {
namespace {

constexpr double kDeg = M_PI / 180.0;

// Landmark positions on the rest dome as (polar angle from the apex, azimuth):
// C at the apex; O1-O4 an outer ring on the axes, Oa-Od the same ring on the diagonals,
// I1-I4 an inner ring on the axes (thesis Fig. 5.2b and 5.12a). Azimuth 90 deg is
// superior (top), 0 deg the patient's right.
const std::map<std::string, std::pair<double, double>>& landmark_angles() {
  static const std::map<std::string, std::pair<double, double>> m = {
      {"C", {0, 0}},
      {"O1", {55 * kDeg, 90 * kDeg}},  {"O2", {55 * kDeg, 0}},          {"O3", {55 * kDeg, 270 * kDeg}},
      {"O4", {55 * kDeg, 180 * kDeg}}, {"Oa", {55 * kDeg, 45 * kDeg}},  {"Ob", {55 * kDeg, 135 * kDeg}},
      {"Oc", {55 * kDeg, 225 * kDeg}}, {"Od", {55 * kDeg, 315 * kDeg}}, {"I1", {28 * kDeg, 90 * kDeg}},
      {"I2", {28 * kDeg, 0}},          {"I3", {28 * kDeg, 270 * kDeg}}, {"I4", {28 * kDeg, 180 * kDeg}}};
  return m;
}

}  // namespace

const std::vector<std::string>& phantom_tumour_names() {
  static const std::vector<std::string> n = {"top", "middle", "bottom", "left", "right"};
  return n;
}

std::vector<std::string> phantom_landmark_set(const std::string& name) {
  const std::vector<std::string> O = {"O1", "O2", "O3", "O4"}, Oa = {"Oa", "Ob", "Oc", "Od"}, I = {"I1", "I2", "I3", "I4"};
  auto cat = [](std::initializer_list<std::vector<std::string>> parts) {
    std::vector<std::string> out;
    for (const auto& p : parts) out.insert(out.end(), p.begin(), p.end());
    return out;
  };
  if (name == "C+O") return cat({{"C"}, O});
  if (name == "O+Oa+I") return cat({O, Oa, I});
  if (name == "O+I") return cat({O, I});
  if (name == "O+Oa") return cat({O, Oa});
  if (name == "Oa+I") return cat({Oa, I});
  std::vector<std::string> out;
  std::stringstream ss(name);
  std::string item;
  while (std::getline(ss, item, ',')) {
    if (!landmark_angles().count(item))
      throw InputError("unknown landmark or landmark set '" + item +
                       "' (sets: C+O, O+Oa+I, O+I, O+Oa, Oa+I; names: C, O1-O4, Oa-Od, I1-I4)");
    out.push_back(item);
  }
  if (out.empty()) throw InputError("empty landmark set");
  return out;
}

PhantomModel make_phantom_model(const PhantomOptions& opt) {
  if (!(opt.width_x > 0 && opt.width_y > 0 && opt.height > 0)) throw InputError("phantom sizes must be positive");
  const double a = opt.width_x / 2, b = opt.width_y / 2, c = opt.height;
  if (!(opt.tumour_radius > 0) || opt.tumour_radius > 0.3 * std::min({a, b, c}))
    throw InputError("tumour radius must be positive and below 30% of the smallest semi-axis");
  PhantomModel m;
  m.surface = make_half_ellipsoid(a, b, c, opt.surface_rings);
  m.rest = tetrahedralize(m.surface, opt.tet);

  // Chest wall: boundary vertices on the base plane (Mesh_3 keeps the sharp rim, so the
  // base is meshed exactly in z = 0).
  const double tol = 1e-6 * c;
  for (int v : boundary_vertices(m.rest))
    if (std::abs(m.rest.V(v, 2)) <= tol) m.chest_wall.push_back(v);
  if (m.chest_wall.size() < 3) throw InputError("phantom: tetrahedralization lost the flat chest wall");

  // Landmarks: the skin vertex nearest to each parametric position.
  std::vector<int> skin;
  for (int v : boundary_vertices(m.rest))
    if (std::abs(m.rest.V(v, 2)) > tol) skin.push_back(v);
  for (const auto& [name, ang] : landmark_angles()) {
    const Vec3 p = half_ellipsoid_point(a, b, c, ang.first, ang.second);
    int best = skin.front();
    for (int v : skin)
      if ((m.rest.V.row(v).transpose() - p).squaredNorm() < (m.rest.V.row(best).transpose() - p).squaredNorm()) best = v;
    m.landmarks[name] = best;
  }

  const double r = opt.tumour_radius;
  const std::map<std::string, Vec3> centres = {{"middle", {0, 0, 0.30 * c}},   {"top", {0, 0.4 * b, 0.25 * c}},
                                               {"bottom", {0, -0.4 * b, 0.25 * c}}, {"left", {-0.4 * a, 0, 0.25 * c}},
                                               {"right", {0.4 * a, 0, 0.25 * c}}};
  for (const auto& [name, centre] : centres) {
    if (centre.z() - r < 0.0) throw InputError("phantom: tumour '" + name + "' would cross the chest wall");
    m.tumours[name] = make_icosphere(centre, r, opt.tumour_subdivisions);
  }
  if (!(opt.gland_axes.minCoeff() > 0) || !(opt.gland_centre_z - opt.gland_axes.z() > 0) ||
      !(opt.gland_centre_z + opt.gland_axes.z() < 1) || !(opt.gland_axes.x() < 1 && opt.gland_axes.y() < 1))
    throw InputError("phantom: the gland ellipsoid must lie inside the breast (0 < centre_z - axis_z, centre_z + axis_z < 1)");
  m.gland = make_icosphere(Vec3::Zero(), 1.0, opt.tumour_subdivisions);
  for (Eigen::Index i = 0; i < m.gland.V.rows(); ++i)
    m.gland.V.row(i) = Vec3(a * opt.gland_axes.x() * m.gland.V(i, 0), b * opt.gland_axes.y() * m.gland.V(i, 1),
                            c * (opt.gland_centre_z + opt.gland_axes.z() * m.gland.V(i, 2))).transpose();
  m.chest_ring = make_chest_ring(a, b, opt.ring_width, 6 * opt.surface_rings);
  return m;
}

}  // namespace btr
