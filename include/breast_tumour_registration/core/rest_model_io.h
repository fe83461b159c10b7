// A rest model file (YAML): the rest shape the experiment suite deforms with its generating
// materials, so the thesis's experiments can run on a user's model as on the built-in
// phantom. Paths are relative to the file; lengths use `units`.
//
//   units: mm
//   rest: rest.vtk                       # tetrahedral mesh of the rest shape (VTK, Medit)
//   chest_wall: chest_wall.txt           # fixed vertex indices of `rest`
//   landmarks: landmark_vertices.txt     # "name index" per line (boundary vertices of `rest`)
//   chest_ring: chest_ring.obj           # optional: rigid skin around the breast (for ICP)
//   tumours: {top: tumour_top_rest.obj}  # name: closed surface inside `rest`
#pragma once

#include <string>

#include "breast_tumour_registration/core/phantom.h"
#include "breast_tumour_registration/core/units.h"

namespace btr {

/// Loads and validates a rest model. Throws InputError naming the file and field at fault.
PhantomModel load_rest_model(const std::string& path);

/// Writes `model` as model.yaml and its files into `dir` (created).
void write_rest_model(const std::string& dir, const PhantomModel& model, LengthUnit unit);

}  // namespace btr
