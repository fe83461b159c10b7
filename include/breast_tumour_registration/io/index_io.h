// Plain-text vertex index lists and landmark correspondence files.
#pragma once

#include <string>
#include <utility>
#include <vector>

#include "breast_tumour_registration/base/types.h"
#include "breast_tumour_registration/base/units.h"

namespace btr {

/// Reads 0-based vertex indices separated by whitespace and/or commas; '#' starts a comment.
std::vector<int> read_index_list(const std::string& path);
void write_index_list(const std::string& path, const std::vector<int>& indices);

/// A landmark correspondence: a prone vertex and either a supine vertex index or a supine point.
struct LandmarkPair {
  int prone_vertex = -1;
  int supine_vertex = -1;  ///< -1 when the supine side is a point
  Vec3 supine_point = Vec3::Zero();  ///< [m], valid when supine_vertex == -1
};

/// Reads a CSV of landmark pairs, one per line: "prone_index,supine_index" or
/// "prone_index,x,y,z" (a supine point, in the given length unit). A header line
/// (any line whose first field is not a number) and '#' comments are skipped.
std::vector<LandmarkPair> read_landmark_pairs(const std::string& path, LengthUnit unit);
void write_landmark_pairs(const std::string& path, const std::vector<LandmarkPair>& pairs, LengthUnit unit);

/// Named vertices (e.g. landmarks C, O1, ...), one per line: "name index" or "name,index".
std::vector<std::pair<std::string, int>> read_named_indices(const std::string& path);
void write_named_indices(const std::string& path, const std::vector<std::pair<std::string, int>>& named);

/// Throws InputError if any index is outside [0, n); `what` names the list in the message.
void check_index_range(const std::vector<int>& indices, long n, const std::string& what);

}  // namespace btr
