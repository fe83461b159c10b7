#include "breast_tumour_registration/io/index_io.h"

#include <cmath>
#include <fstream>
#include <algorithm>
#include <limits>
#include <sstream>

#include "breast_tumour_registration/base/errors.h"
#include "breast_tumour_registration/base/strings.h"

namespace btr {
namespace {

std::vector<std::string> split_fields(std::string line) {
  line = line.substr(0, line.find('#'));
  for (char& c : line)
    if (c == ',' || c == ';' || c == '\t' || c == '\r') c = ' ';
  std::istringstream ss(line);
  std::vector<std::string> out;
  std::string t;
  while (ss >> t) out.push_back(t);
  return out;
}

// An index: a whole number that fits an int (indices of 2^31 and above used to wrap to valid
// vertices through a narrowing cast).
bool parse_int(const std::string& s, long& v) {
  const auto x = parse_integer(s);
  if (x) v = *x;
  return x.has_value();
}

bool parse_real(const std::string& s, double& v) {
  const auto x = parse_number(s);
  if (x) v = *x;
  return x.has_value();
}

}  // namespace

std::vector<int> read_index_list(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError("cannot open index list '" + path + "': file missing or unreadable");
  std::vector<int> out;
  std::string line;
  size_t ln = 0;
  while (std::getline(in, line)) {
    ++ln;
    for (const auto& f : split_fields(line)) {
      long v = 0;
      if (!parse_int(f, v))
        throw InputError(path + ":" + std::to_string(ln) + ": '" + f + "' is not a vertex index (0 to 2^31 - 1)");
      if (v < 0) throw InputError(path + ":" + std::to_string(ln) + ": negative vertex index " + f);
      out.push_back(static_cast<int>(v));
    }
  }
  return out;
}

void write_index_list(const std::string& path, const std::vector<int>& indices) {
  std::ofstream out(path);
  if (!out) throw InputError("cannot write '" + path + "'");
  for (size_t i = 0; i < indices.size(); ++i) out << indices[i] << ((i + 1) % 16 == 0 ? '\n' : ' ');
  out << '\n';
}

std::vector<std::pair<std::string, int>> read_named_indices(const std::string& path) {
  std::ifstream in(path);
  if (!in) throw InputError("cannot open named vertex file '" + path + "': file missing or unreadable");
  std::vector<std::pair<std::string, int>> out;
  std::string line;
  size_t ln = 0;
  while (std::getline(in, line)) {
    ++ln;
    const auto f = split_fields(line);
    if (f.empty()) continue;
    long v = 0;
    if (f.size() != 2 || !parse_int(f[1], v) || v < 0)
      throw InputError(path + ":" + std::to_string(ln) + ": expected 'name vertex_index', got '" + line + "'");
    for (const auto& [name, index] : out)
      if (name == f[0]) throw InputError(path + ":" + std::to_string(ln) + ": name '" + f[0] + "' given twice");
    out.emplace_back(f[0], static_cast<int>(v));
  }
  if (out.empty()) throw InputError(path + ": no named vertices");
  return out;
}

void write_named_indices(const std::string& path, const std::vector<std::pair<std::string, int>>& named) {
  std::ofstream out(path);
  if (!out) throw InputError("cannot write '" + path + "'");
  out << "# name vertex_index (0-based)\n";
  for (const auto& [name, index] : named) out << name << ' ' << index << '\n';
}

std::vector<LandmarkPair> read_landmark_pairs(const std::string& path, LengthUnit unit) {
  std::ifstream in(path);
  if (!in) throw InputError("cannot open landmark file '" + path + "': file missing or unreadable");
  const double s = metres_per_unit(unit);
  std::vector<LandmarkPair> out;
  std::string line;
  size_t ln = 0;
  bool header_seen = false;
  while (std::getline(in, line)) {
    ++ln;
    const auto f = split_fields(line);
    if (f.empty()) continue;
    long a = 0;
    if (!parse_int(f[0], a)) {
      // A header is the first line, and none of its fields is a number: a malformed first
      // row is an error, not a header.
      double dummy = 0;
      const bool header = out.empty() && !header_seen &&
                          std::none_of(f.begin(), f.end(), [&](const std::string& x) { return parse_real(x, dummy); });
      header_seen = true;
      if (header) continue;
      throw InputError(path + ":" + std::to_string(ln) + ": '" + f[0] + "' is not a prone vertex index (0 to 2^31 - 1)");
    }
    header_seen = true;
    if (a < 0) throw InputError(path + ":" + std::to_string(ln) + ": negative prone vertex index");
    LandmarkPair p;
    p.prone_vertex = static_cast<int>(a);
    long b = 0;
    if (f.size() == 2 && parse_int(f[1], b) && b >= 0) {
      p.supine_vertex = static_cast<int>(b);
    } else if (f.size() == 4) {
      for (int c = 0; c < 3; ++c) {
        double v = 0;
        if (!parse_real(f[1 + c], v) || !std::isfinite(v))
          throw InputError(path + ":" + std::to_string(ln) + ": '" + f[1 + c] + "' is not a coordinate");
        p.supine_point[c] = v * s;
      }
    } else {
      throw InputError(path + ":" + std::to_string(ln) +
                       ": expected 'prone_index,supine_index' or 'prone_index,x,y,z', got " +
                       std::to_string(f.size()) + " fields");
    }
    out.push_back(p);
  }
  if (out.empty()) throw InputError(path + ": no landmark pairs");
  return out;
}

void write_landmark_pairs(const std::string& path, const std::vector<LandmarkPair>& pairs, LengthUnit unit) {
  std::ofstream out(path);
  if (!out) throw InputError("cannot write '" + path + "'");
  out.precision(17);
  const double inv = 1.0 / metres_per_unit(unit);
  bool points = false;
  for (const auto& p : pairs) points |= p.supine_vertex < 0;
  out << (points ? "prone_index,x,y,z\n" : "prone_index,supine_index\n");
  for (const auto& p : pairs) {
    if (p.supine_vertex >= 0 && !points)
      out << p.prone_vertex << ',' << p.supine_vertex << '\n';
    else
      out << p.prone_vertex << ',' << p.supine_point.x() * inv << ',' << p.supine_point.y() * inv << ','
          << p.supine_point.z() * inv << '\n';
  }
}

void check_index_range(const std::vector<int>& indices, long n, const std::string& what) {
  for (size_t i = 0; i < indices.size(); ++i)
    if (indices[i] < 0 || indices[i] >= n)
      throw InputError(what + ": entry " + std::to_string(i) + " is vertex " + std::to_string(indices[i]) +
                       ", out of range for a mesh with " + std::to_string(n) + " vertices");
}

}  // namespace btr
