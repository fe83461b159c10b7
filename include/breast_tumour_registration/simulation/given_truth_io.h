// Prone and supine configurations of a rest model made elsewhere (another FEM code, a measured
// pair): what `btr_experiments --truth` runs the experiments on instead of configurations its
// own solver generates. Paths are relative to the file; lengths use `units`.
//
//   units: mm                             # required: m or mm
//   configurations:
//     - youngs_modulus: 1000              # the generating modulus it stands for [Pa] (a CSV column)
//       prone: E1000/prone_volume.vtk     # the rest model's mesh, its vertices prone (same tetrahedra)
//       supine: E1000/supine_volume.vtk   # and supine
//       tumours:                          # every tumour of the rest model, in both positions
//         central: {prone: E1000/tumour_central_prone.obj, supine: E1000/tumour_central_supine.obj}
//
// bench/make_independent_truth.py writes one beside its model.yaml (SfePy's P2 solutions at the
// rest mesh's vertices).
#pragma once

#include <map>
#include <string>

#include "breast_tumour_registration/simulation/phantom.h"
#include "breast_tumour_registration/simulation/phantom_scene.h"

namespace btr {

/// The configurations of `path`, by the Young's modulus each stands for. Throws InputError
/// naming the file and field at fault: a volume whose vertices or tetrahedra are not
/// `model`'s, a tumour the model does not have or a model tumour missing, a modulus given
/// twice or not positive, missing units.
std::map<double, PhantomConfigurations> load_given_configurations(const std::string& path, const PhantomModel& model);

}  // namespace btr
