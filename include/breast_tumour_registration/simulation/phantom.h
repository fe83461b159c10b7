// The thesis's synthetic breast phantom (Sec. 5.2.1): a half ellipsoid of 72 x 149 x 149 mm
// whose flat base is the fixed chest wall, a rigid ring of chest skin around the base,
// spherical tumours at five locations and the thesis's landmark sets.
//
// Frame: the chest wall is the plane z = 0, the breast extends towards +z (anterior),
// x is the patient's left-right axis and y the inferior-superior axis. Prone gravity
// points along +z (the breast hangs away from the chest), supine gravity along -z.
#pragma once

#include <map>
#include <string>
#include <vector>

#include "breast_tumour_registration/base/types.h"
#include "breast_tumour_registration/geometry/tetrahedralize.h"

namespace btr {

struct PhantomOptions {
  double width_x = 0.149, width_y = 0.149, height = 0.072;  ///< [m]
  int surface_rings = 24;        ///< resolution of the input half-ellipsoid surface
  TetrahedralizeOptions tet;     ///< cell_size sets the FEM resolution
  double tumour_radius = 0.010;  ///< [m]
  int tumour_subdivisions = 3;
  double ring_width = 0.04;      ///< width of the chest-skin ring around the base [m]
  /// Fibroglandular region: an ellipsoid centred on the breast's axis at gland_centre_z times
  /// the height, with semi-axes gland_axes times (a, b, height); used when a generating
  /// material gives it its own stiffness (PhantomSceneOptions::gland_youngs_modulus).
  double gland_centre_z = 0.45;
  Vec3 gland_axes = Vec3(0.45, 0.45, 0.30);
};

struct PhantomModel {
  SurfaceMesh surface;                        ///< input half ellipsoid (rest)
  TetMesh rest;                               ///< its tetrahedralization
  std::vector<int> chest_wall;                ///< tet vertices on the base plane (fixed)
  SurfaceMesh chest_ring;                     ///< rigid chest skin (no FEM; for rigid alignment)
  std::map<std::string, SurfaceMesh> tumours; ///< rest tumour spheres: top, middle, bottom, left, right
  SurfaceMesh gland;                          ///< rest fibroglandular region (closed; empty for a model read without one)
  std::map<std::string, int> landmarks;       ///< C, O1-O4, Oa-Od, I1-I4 -> tet boundary vertex
  /// The tissue layout the method's model is given (a rest model file's `regions`: a segmented
  /// MRI's): each run's scene gives these labels' tetrahedra `relative_stiffness` times the
  /// method's E (scaled with it where E is estimated). Empty: the method's model is homogeneous.
  struct MethodRegion {
    std::string name;
    int label = 0;                   ///< cell label of `rest`
    double relative_stiffness = 1;   ///< times the method's Young's modulus
  };
  std::vector<MethodRegion> method_regions;
  std::vector<int> rest_labels;               ///< cell label per rest tetrahedron (with method_regions)
  Vec3 prone_gravity = Vec3(0, 0, 9.81);      ///< [m/s^2] model frame: the phantom lies prone towards +z
  Vec3 supine_gravity = Vec3(0, 0, -9.81);    ///< [m/s^2] model frame
  std::vector<std::string> warnings;          ///< what loading repaired
};

/// Names of the five tumour locations and of the thesis's landmark sets.
const std::vector<std::string>& phantom_tumour_names();
/// Landmark set by name: "C+O" (the five default), "O+Oa+I", "O+I", "O+Oa", "Oa+I";
/// or a comma separated list of landmark names. Throws InputError for unknown names.
std::vector<std::string> phantom_landmark_set(const std::string& name);

/// Builds the rest model. Throws InputError for bad options.
PhantomModel make_phantom_model(const PhantomOptions& opt);

}  // namespace btr
