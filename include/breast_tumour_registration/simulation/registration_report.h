// Writes a registration's outputs: deformed tetrahedral mesh, skin surface and tumours in
// the supine frame (OBJ, PLY, VTK), a JSON report, and a PNG cross-section.
#pragma once

#include <string>

#include "breast_tumour_registration/registration/registration_pipeline.h"

namespace btr {

/// The report as JSON text (lengths in millimetres, times in seconds, as labelled).
std::string registration_report_json(const Scene& scene, const RegistrationModel& model, const RegistrationResult& r,
                                     double prepare_seconds);

/// Creates `dir` and checks that it is writable, before any work (issue 11: an unwritable
/// --out was found only after the whole registration). InputError naming --out otherwise.
void prepare_output_folder(const std::string& dir);

/// Writes every output into `dir` (created); returns the list of files written.
/// The 95 % region of a Gaussian point (centre, covariance [m^2]) as a closed surface: the
/// ellipsoid with semi-axes sqrt(chi2_3(0.95) lambda_i) along the eigenvectors.
SurfaceMesh uncertainty_ellipsoid(const Vec3& centre, const Mat3& covariance);

std::vector<std::string> write_registration_outputs(const std::string& dir, const Scene& scene,
                                                    const RegistrationModel& model, const RegistrationResult& r,
                                                    double prepare_seconds);

}  // namespace btr
