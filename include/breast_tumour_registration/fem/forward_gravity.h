// The forward equilibrium of a body under gravity from a changing rest shape, solved many
// times on one mesh: one Hessian assembler and Newton solver (so one CHOLMOD symbolic
// analysis) for every solve, and load continuation when one load step does not converge (a
// soft body sagging far: the gravity ramped up from zero in adaptive fractions, each solve
// warm-started from the last). The unloaded-shape estimate and the stiffness estimate are
// sequences of such solves.
#pragma once

#include <memory>
#include <utility>
#include <vector>

#include "breast_tumour_registration/fem/elastic_energy.h"
#include "breast_tumour_registration/fem/newton_solver.h"
#include "breast_tumour_registration/fem/quadratic_elastic_energy.h"
#include "breast_tumour_registration/fem/quadratic_tetrahedra.h"

namespace btr {

struct ForwardGravityOptions {
  /// Of each solve (force_scale 0: the body's weight). A gravity equilibrium that can only be
  /// reached by inverting elements is no equilibrium to keep, and the load continuation needs
  /// that failure early: a step the no-new-inversion rule cuts to 1/8 or less lets the line
  /// search invert (inversion_stall_alpha), and once more than 0.2 % of the tetrahedra are
  /// newly inverted, the allowance a solve may end with, the solve ends there, failed
  /// (abandon_inverted_fraction). Measured on SfePy's fat 300 Pa body with the nodal volume
  /// term, one stiffness candidate's unload (640 Pa): 807 Newton iterations before, 173 after,
  /// the same unloaded shape; its solves had crawled on steps the rule cut to 1e-5, then folded
  /// up to 427 inverted tetrahedra, to the iteration cap.
  NewtonOptions newton = [] {
    NewtonOptions o;
    o.inversion_stall_alpha = 1.0 / 8;
    o.abandon_inverted_fraction = o.max_inverted_fraction_after_stall;
    return o;
  }();
  /// The first load fraction of a continuation; the step is grown 1.5x after a converged
  /// fraction and the failed step halved after a failed one (so a step clipped at the full
  /// load is not retried as it was); below min_load_fraction the solve has failed.
  double first_load_fraction = 0.25;
  double min_load_fraction = 1.0 / 64;
  /// Linear or quadratic elements. Quadratic: the rest shape and the loaded shape given and
  /// returned are still the linear mesh's vertices, the rest straight-sided; the edge nodes stay
  /// inside (each solve starts them from the last converged one's bulge; quadratic_nodes() gives
  /// them), the volume term is the element's at the quadrature points (volume_form and the
  /// nodal element share do not apply) and a shared solver is not used (another pattern).
  ElementOrder element_order = ElementOrder::Linear;
  int quadrature_degree = 5;  ///< quadratic elements: tet_quadrature(2 or 5)
  QuadraticVolume quadratic_volume = QuadraticVolume::Quadrature;  ///< quadratic elements: where the volume term acts
};

class ForwardGravity {
 public:
  /// Throws InputError for a fixed vertex out of range or an unresolved volume form.
  /// `shared`: a Newton solver already bound to this problem's Hessian pattern (these tets and
  /// fixed vertices, the elastic energy's cliques), e.g. an engine's cached one, used instead of
  /// building one, so its symbolic analysis is reused; its numeric factor is dropped first, so
  /// the solves are those of a new solver. Null: one is built on the first solve.
  ForwardGravity(const Tetrahedra& T, Eigen::Index vertices, const std::vector<int>& fixed,
                 std::vector<StableNeoHookean> materials, std::vector<int> material_of, VolumeForm volume_form,
                 double nodal_element_share, double density, ForwardGravityOptions options = {},
                 NewtonSolver* shared = nullptr);

  /// The equilibrium of rest shape X under `gravity` [m/s^2] with the fixed vertices at X's
  /// positions; x is the start and receives the equilibrium. Returns the Newton iterations it
  /// took; throws SolverError (x unchanged) when even the smallest load fraction fails.
  int solve(const Points& X, const Vec3& gravity, Points& x);

  bool is_fixed(Eigen::Index v) const { return fixed_[static_cast<size_t>(v)]; }
  int newton_iterations() const { return newton_iterations_; }  ///< over all solves
  /// The last Newton solve's result (of the last load fraction, when continued): its stop reason.
  const NewtonResult& last_newton() const { return last_; }
  int load_steps() const { return load_steps_; }                ///< continuation fractions solved, over all solves
  /// Every continuation step tried, in order, over all solves: (load fraction, converged).
  const std::vector<std::pair<double, bool>>& continuation_steps() const { return continuation_steps_; }
  /// Quadratic elements: the mesh and every node's position at the last converged solve (corners
  /// first, then edge nodes), for evaluating the quadratic field (quadratic_interpolate).
  const QuadraticTetMesh& quadratic_mesh() const { return quadratic_; }
  const Points& quadratic_nodes() const { return quadratic_x_; }

 private:
  NewtonResult solve_once(const Points& X, const Vec3& gravity, Points& x);
  NewtonResult solve_once_quadratic(const Points& X, const Vec3& gravity, Points& x);

  TetMesh rest_;
  std::vector<bool> fixed_;
  std::vector<StableNeoHookean> materials_;
  std::vector<int> material_of_;
  VolumeForm volume_form_;
  double nodal_element_share_;
  double density_;
  ForwardGravityOptions opt_;
  std::unique_ptr<NewtonSolver> own_;
  NewtonSolver* solver_ = nullptr;  ///< own_, or the shared one
  int newton_iterations_ = 0, load_steps_ = 0;
  NewtonResult last_;
  std::vector<std::pair<double, bool>> continuation_steps_;
  QuadraticTetMesh quadratic_;
  std::vector<bool> quadratic_fixed_;
  Points bulge_;        ///< per edge node: its offset from its edge's midpoint at the last converged solve
  Points quadratic_x_;  ///< every node at the last converged solve
};

}  // namespace btr
