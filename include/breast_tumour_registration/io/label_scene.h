// From a segmented prone image to a registration scene: the label table (which label value
// is which tissue), the multi-material mesh (label_mesher.h) and the scene folder it writes.
//
// The label table (YAML; every key optional, defaults shown):
//   fat: [1]            # label values (or Slicer segment names) of each tissue
//   gland: [2]
//   tumour: [3]         # each connected tumour region becomes a tumour of the scene
//   muscle: 4           # the pectoral muscle: its interface with the breast is the chest wall;
//                       # `muscle: none` fixes the posterior-most skin instead
//   skin: []
//   ignore: []          # other structures, left outside the model (any label not listed
//                       # anywhere is an error: the table must account for every label)
//   stiffness: {gland: 1, tumour: 1, skin: 1}   # relative to fat, i.e. to material.youngs_modulus;
//                       # 1 (homogeneous, the thesis's model) unless the table says otherwise, as a
//                       # stiffer tumour is off in a scene unless given. Published ratios are about 2
//                       # for gland and 5 to 10 for tumours (issue 13); a wrong ratio costs (BENCHMARKS.md)
//
// The scene is written in RAS millimetres (`patient_frame: RAS`), the supine gravity along
// posterior and, for a prone image, the prone gravity along anterior (which plans `unload`).
#pragma once

#include <map>
#include <optional>
#include <string>
#include <vector>

#include "breast_tumour_registration/geometry/label_mesher.h"
#include "breast_tumour_registration/geometry/label_volume.h"

namespace btr {

struct LabelTable {
  std::vector<int> fat = {1}, gland = {2}, tumour = {3}, skin = {}, ignore = {};
  int muscle = 4;  ///< -1: none
  double gland_stiffness = 1, tumour_stiffness = 1, skin_stiffness = 1;  ///< relative to fat
};

/// Reads a label table; entries may be label values or segment names of `v` (a .seg.nrrd's
/// SegmentN_Name, case-insensitive). InputError naming the file and the key.
LabelTable read_label_table(const std::string& path, const LabelVolume& v);
/// Checks the table against the volume: every label present is accounted for, and no label
/// is given two roles. InputError naming `source`.
void check_label_table(const LabelTable& t, const LabelVolume& v, const std::string& source);

/// A known tumour (a phantom's, or another segmentation's): its prone and supine surfaces.
struct TumourTruthFiles {
  std::string name, prone, supine;  ///< surfaces in the scene's frame (RAS), millimetres
};

struct LabelSceneOptions {
  LabelMeshOptions mesh;          ///< tissue, tumour and muscle come from the table
  std::string prone_landmarks;    ///< Slicer point list on the prone skin (copied into the scene)
  std::string supine_landmarks;   ///< its supine counterpart, matched by label
  std::string supine_surface;     ///< supine surface scan (RAS, supine_units), copied
  std::string supine_cloud;       ///< or a supine point cloud (.xyz, .ply), copied
  std::string supine_units = "mm";
  bool prone_image = true;        ///< the image was taken prone: state prone_gravity (plans unload)
  double youngs_modulus = 3400;   ///< fat [Pa] (the thesis's default)
  double poisson_ratio = 0.49;
  std::string preset = "balanced";
  /// Known tumours: each meshed tumour takes the name and the supine ground truth of the one
  /// whose prone centroid is nearest (within kTruthMatchDistance), for validation.
  std::vector<TumourTruthFiles> truth;
};

/// How far a meshed tumour's centroid may be from the known prone tumour it is matched to [m].
constexpr double kTruthMatchDistance = 0.005;

struct LabelSceneSummary {
  long tetrahedra = 0, vertices = 0, chest_wall_vertices = 0;
  bool chest_wall_from_muscle = false;
  std::vector<std::pair<std::string, Vec3>> tumour_centroids;  ///< RAS [m]
  double mesh_seconds = 0;
  std::vector<std::string> warnings;
};

/// Meshes the label map and writes DIR/prone.vtk (labels), chest_wall.txt, the tumours'
/// surfaces, copies of the supine inputs and DIR/scene.yaml. InputError naming the input at fault.
LabelSceneSummary write_scene_from_labels(const std::string& dir, const LabelVolume& v, const LabelTable& table,
                                          const LabelSceneOptions& opt);

}  // namespace btr
