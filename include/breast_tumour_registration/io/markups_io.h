// 3D Slicer point lists ("fiducials"): the markups JSON (.mrk.json, schema 1.0) and the
// older markups CSV (.fcsv). Points come back in the patient frame asked for, in metres; the
// file's own coordinate system (LPS or RAS) and units are applied here, once.
#pragma once

#include <string>
#include <vector>

#include "breast_tumour_registration/geometry/label_volume.h"

namespace btr {

struct NamedPoint {
  std::string label;
  Vec3 position = Vec3::Zero();  ///< [m], in the frame asked for
};

/// Reads the control points of the first point list in `path` (.mrk.json or .fcsv). Points
/// without a defined position (positionStatus "missing"/"undefined") are skipped. InputError
/// naming the file for: an unknown extension, malformed JSON/CSV, no point list, a coordinate
/// system other than LPS/RAS, units other than mm/m, no points, duplicate or empty labels.
/// An .fcsv without a CoordinateSystem line is RAS (Slicer before 4.11).
std::vector<NamedPoint> read_markups(const std::string& path, PatientFrame frame);

/// Writes a Slicer point list (.mrk.json) in millimetres, in `file_frame`; `points` are given
/// in `points_frame`. `descriptions` (optional, one per point) go to each point's description.
void write_markups(const std::string& path, const std::vector<NamedPoint>& points, PatientFrame points_frame,
                   PatientFrame file_frame = PatientFrame::LPS, const std::vector<std::string>& descriptions = {});

struct MatchedPoints {
  std::vector<std::string> labels;
  Points first, second;  ///< one row per matched label, in the order of the first list
  std::vector<std::string> unmatched;  ///< labels found in only one list
};
/// Pairs two point lists by label.
MatchedPoints match_by_label(const std::vector<NamedPoint>& first, const std::vector<NamedPoint>& second);

}  // namespace btr
