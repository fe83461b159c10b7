#include "breast_tumour_registration/registration/unload_step.h"

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/units.h"
#include "breast_tumour_registration/fem/tet_kinematics.h"
#include "breast_tumour_registration/geometry/validation.h"
#include "breast_tumour_registration/registration/step_solvers.h"

namespace btr {

void set_rest_shape(RegistrationModel& model, const Points& rest, const StepReport& report, const Vec3& unloaded_under,
                    const Points& nodes) {
  if (rest.rows() != model.prone.rows() || rest.cols() != 3 || !rest.allFinite())
    throw InputError("unload: the rest shape has " + std::to_string(rest.rows()) + " finite vertices, the model " +
                     std::to_string(model.prone.rows()));
  if (count_inverted(rest, model.rest.T) > 0) throw InputError("unload: the rest shape has inverted elements");
  model.rest.V = rest;
  model.volume = 0;
  for (Eigen::Index t = 0; t < model.rest.T.rows(); ++t) model.volume += tet_signed_volume(model.rest.V, model.rest.T, t);
  model.unload = report;
  model.unloaded_under = unloaded_under;
  model.unloaded_nodes = nodes;
}

UnloadProblem unload_problem(const RegistrationModel& model, const TetMesh& loaded, const Vec3& gravity) {
  UnloadProblem pb;
  pb.loaded = &loaded;
  pb.fixed = model.chest_wall;
  pb.materials = model.materials;
  pb.material_of = model.material_of;
  pb.volume_form = model.volume_form;
  pb.nodal_element_share = model.material.nodal_element_share;
  pb.density = model.material.density;
  pb.gravity = gravity;
  return pb;
}

StepReport unload_report(const UnloadResult& u, const Points& prone) {
  StepReport rep;
  rep.name = "unload";
  rep.converged = u.converged;
  rep.stop_reason = u.stop_reason;
  rep.iterations = u.newton_iterations;
  rep.outer_iterations = u.iterations;
  rep.seconds = u.seconds;
  const double moved = u.rest.rows() == prone.rows() ? (u.rest - prone).rowwise().norm().maxCoeff() : 0.0;
  rep.unload = {u.max_mismatch, u.forward_solve_equivalents, moved, u.load_steps, u.elements};
  return rep;
}

UnloadOptions with_model_elements(UnloadOptions options, const RegistrationModel& model) {
  options.forward.element_order = model.material.unload_element_order;
  options.forward.quadrature_degree = kUnloadQuadratureDegree;  // read by quadratic elements only
  return options;
}

void refine_with_model_elements(const RegistrationModel& model, const TetMesh& loaded, const Vec3& gravity,
                                const UnloadOptions& options, UnloadResult& unload) {
  if (model.material.unload_element_order == ElementOrder::Linear) return;
  UnloadProblem pb = unload_problem(model, loaded, gravity);
  pb.initial_rest = &unload.rest;
  UnloadOptions o = with_model_elements(options, model);
  o.max_forward_solves = kModelElementsForwardSolves;
  o.max_stages = 0;  // from the linear shape it converges directly where it converges at all (below)
  UnloadResult q = estimate_unloaded_shape(pb, o);
  const std::string order = to_string(model.material.unload_element_order);
  q.seconds += unload.seconds;
  if (q.converged || q.max_mismatch < unload.max_mismatch) {
    q.stop_reason += " (" + order + " elements, from the linear shape)";
    unload = std::move(q);
  } else {
    unload.seconds = q.seconds;
    unload.stop_reason += "; with " + order + " elements it did not converge (" + q.stop_reason + "), so the linear shape is used";
  }
}

StepReport unload_model(RegistrationModel& model, const Vec3& prone_gravity, const UnloadOptions& options,
                        StepSolvers* cache) {
  if (!prone_gravity.allFinite() || !(prone_gravity.norm() > 0))
    throw InputError("prone_gravity: must be a finite, non-zero vector [m/s^2]");
  const TetMesh loaded{model.prone, model.rest.T};
  UnloadProblem pb = unload_problem(model, loaded, prone_gravity);
  if (cache) pb.solver = &cache->gravity(model);
  // With linear elements first; quadratic ones (another solver, another pattern) start from there.
  UnloadOptions linear = options;
  linear.forward.element_order = ElementOrder::Linear;
  UnloadResult u = estimate_unloaded_shape(pb, linear);
  if (u.converged) refine_with_model_elements(model, loaded, prone_gravity, options, u);

  StepReport rep = unload_report(u, model.prone);
  // The prone shape as rest misses the prone shape by about the sag; the estimate is kept when
  // it does better than that (always, when converged).
  const double prone_as_rest_mismatch = u.inverse_gravity_lift;
  const bool better = u.converged || (!u.mismatch_history.empty() && u.max_mismatch < prone_as_rest_mismatch);
  if (!better) {
    rep.note = "no unloaded shape better than the prone shape was found (" + u.stop_reason +
               "); the prone shape stays the rest shape";
    rep.unload.rest_change = 0;
    model.unload = rep;
    model.unloaded_under = Vec3::Zero();  // the rest shape is the prone shape
    model.unloaded_nodes = Points();
    return rep;
  }
  if (!u.converged)
    rep.note = "stopped before converging (" + u.stop_reason + "); its best estimate reproduces the prone shape within " +
               format_mm(u.max_mismatch, 2) + " (the prone shape as rest: about " + format_mm(prone_as_rest_mismatch, 1) +
               ") and is used";
  set_rest_shape(model, u.rest, rep, prone_gravity, u.resimulated_nodes);
  return rep;
}

}  // namespace btr
