// A segmented image of a phantom, made at test time so that the label-map path needs no
// patient data (issue 15): the prone phantom rasterized into a RAS label map (fat, gland and
// tumour from the phantom's own tissue labels and tumour surfaces, a slab of pectoral muscle
// behind the chest wall), with the landmarks as Slicer point lists and the supine side and
// its truth moved into the same RAS frame.
//
// Frame: the phantom's (chest wall z = 0, breast towards +z, x left-right, y inferior-
// superior) placed in RAS by kPhantomToRas: x stays, +z (anterior) becomes +y, +y becomes -z.
#pragma once

#include <string>

#include "breast_tumour_registration/geometry/label_volume.h"
#include "breast_tumour_registration/io/label_scene.h"
#include "breast_tumour_registration/io/scene.h"

namespace btr {

/// Rotation taking phantom coordinates to RAS.
Mat3 phantom_to_ras();

struct LabelPhantomOptions {
  Vec3 voxel_size = Vec3::Constant(0.001);  ///< along RAS x, y, z [m]
  /// The grid grows (air around the breast, centred) to at least this many voxels, e.g. an MRI
  /// field of view of 512 x 512 x 160; 0: just the breast, the muscle and a margin.
  Eigen::Vector3i min_voxels = Eigen::Vector3i::Zero();
  double muscle_thickness = 0.006;  ///< pectoral slab behind the chest wall [m]
  double margin = 0.004;            ///< air around the breast [m]
  int fat = 1, gland = 2, tumour = 3, muscle = 4;  ///< label values (LabelTable's defaults)
  PatientFrame markups_frame = PatientFrame::LPS;  ///< the frame the point lists are written in (Slicer's)
};

struct LabelPhantomFiles {
  std::string label_map, prone_landmarks, supine_landmarks, supine_surface;
  std::vector<TumourTruthFiles> tumour_truth;  ///< the phantom's tumours, prone and supine (RAS, mm)
  LabelVolume volume;
};

/// Rasterizes the phantom scene `scene_yaml` (as btr_phantom writes it: prone.vtk with its
/// tissue labels when heterogeneous, tumours, landmarks) into `dir`: prone_labels.nii.gz,
/// prone_landmarks.mrk.json, supine_landmarks.mrk.json, supine_surface.obj and
/// tumour_<name>_prone.obj / _supine.obj, all in RAS. InputError for a scene it cannot rasterize.
LabelPhantomFiles write_label_phantom(const std::string& scene_yaml, const std::string& dir, const LabelPhantomOptions& opt = {});
/// The same for a loaded scene with its prone tetrahedra (e.g. a surface scene meshed by
/// with_simulation_mesh, its prone_labels set): its chest wall must be the plane z = 0.
LabelPhantomFiles write_label_phantom(const Scene& s, const std::string& dir, const LabelPhantomOptions& opt = {});

}  // namespace btr
