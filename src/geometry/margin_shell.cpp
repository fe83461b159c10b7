#include "breast_tumour_registration/geometry/margin_shell.h"

#include <cmath>
#include <string>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/geometry/metrics.h"
#include "breast_tumour_registration/geometry/validation.h"
#include "breast_tumour_registration/geometry/vertex_normals.h"

namespace btr {

SurfaceMesh margin_shell(const SurfaceMesh& surface, const std::vector<double>& grow) {
  if (static_cast<Eigen::Index>(grow.size()) != surface.V.rows())
    throw InputError("margin shell: " + std::to_string(grow.size()) + " grow values for " +
                     std::to_string(surface.V.rows()) + " vertices");
  for (double g : grow)
    if (!std::isfinite(g) || g < 0) throw InputError("margin shell: grow values must be finite and >= 0 [m]");
  validate_surface(surface, "margin shell");  // closed and consistently oriented
  const double volume = enclosed_volume(surface);
  if (!std::isfinite(volume) || volume == 0) throw InputError("margin shell: the surface encloses no volume");
  // enclosed_volume is positive for an outward-oriented surface: an inward one's normals are flipped.
  const Points n = vertex_normals(surface) * (volume > 0 ? 1.0 : -1.0);
  SurfaceMesh shell = surface;
  for (Eigen::Index v = 0; v < shell.V.rows(); ++v) shell.V.row(v) += grow[static_cast<size_t>(v)] * n.row(v);
  return shell;
}

}  // namespace btr
