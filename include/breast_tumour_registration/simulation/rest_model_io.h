// A rest model file (YAML): the rest shape the experiment suite deforms with its generating
// materials, so the thesis's experiments can run on a user's model as on the built-in
// phantom. Paths are relative to the file; lengths use `units`.
//
//   units: mm                            # required: m or mm
//   rest: rest.vtk                       # tetrahedral mesh of the rest shape (VTK, Medit), or
//   surface: rest.obj                    #   a closed surface, tetrahedralized at
//   cell_size_mm: 6                      #   this size (default 6)
//   chest_wall: chest_wall.txt           # fixed vertex indices of `rest` (or of `surface`)
//   landmarks: landmark_vertices.txt     # "name index" per line (surface vertices of `rest` or `surface`)
//   chest_ring: chest_ring.obj           # optional: rigid skin around the breast (for ICP)
//   tumours: {top: tumour_top_rest.obj}  # name: closed surface inside the rest shape
//   gravity:                             # required, in the model's frame [m/s^2]
//     prone: [0, 0, 9.81]                #   the pose the prone scan was taken in
//     supine: [0, 0, -9.81]              #   the pose of surgery
#pragma once

#include <string>

#include "breast_tumour_registration/base/units.h"
#include "breast_tumour_registration/simulation/phantom.h"

namespace btr {

/// Loads and validates a rest model. Throws InputError naming the file and field at fault
/// (unknown keys with the nearest valid one, wrong types, missing units or gravity, a mesh
/// whose size says the units are wrong); flipped surface faces are repaired (model.warnings).
PhantomModel load_rest_model(const std::string& path);

/// Writes `model` as model.yaml and its files into `dir` (created).
void write_rest_model(const std::string& dir, const PhantomModel& model, LengthUnit unit);

}  // namespace btr
