// Shared pieces of the mesh-format readers and writers, internal to the io layer: files opened
// with errors that name them, number tokens parsed with their file and line, a token stream for
// the formats whose records span lines, and the index checks every format applies.
#pragma once

#include <fstream>
#include <string>
#include <vector>

#include "breast_tumour_registration/base/types.h"

namespace btr {
namespace mesh_format {

std::ifstream open_in(const std::string& path, bool binary = false);
/// Text output at full double precision.
std::ofstream open_out(const std::string& path, bool binary = false);
[[noreturn]] void fail(const std::string& path, size_t line, const std::string& what);
double parse_double(const std::string& tok, const std::string& path, size_t line);
long parse_long(const std::string& tok, const std::string& path, size_t line);

// The whitespace-separated tokens of a text file with their line numbers, for the formats
// whose records span lines (OFF, legacy VTK, Medit).
class TokenStream {
 public:
  struct Token {
    std::string text;
    size_t line;
  };
  /// hash_comments: '#' starts a comment; skip_line (1-based, 0: none) is ignored entirely;
  /// check_first_line, when given, must start line 1.
  TokenStream(const std::string& path, bool hash_comments, size_t skip_line = 0, const char* check_first_line = nullptr);
  bool done() const { return pos_ >= tokens_.size(); }
  size_t remaining() const { return tokens_.size() - pos_; }
  const Token& peek() const { return tokens_[pos_]; }
  const Token& next(const char* what) {
    if (done()) fail(path_, last_line_, std::string("unexpected end of file, expected ") + what);
    return tokens_[pos_++];
  }
  long next_long(const char* what) {
    const Token& t = next(what);
    return parse_long(t.text, path_, t.line);
  }
  double next_double(const char* what) {
    const Token& t = next(what);
    return parse_double(t.text, path_, t.line);
  }
  /// A count from a header, checked against what the file holds before anything is allocated:
  /// each item needs at least tokens_per_item more values.
  long next_count(const char* what, long tokens_per_item) {
    const Token& t = next(what);
    const long n = parse_long(t.text, path_, t.line);
    if (n < 0) fail(path_, t.line, std::string(what) + " " + t.text + " is negative");
    const size_t left = tokens_.size() - pos_;
    if (static_cast<unsigned long>(n) * static_cast<unsigned long>(tokens_per_item) > left)
      fail(path_, t.line, std::string(what) + " " + t.text + " needs at least " +
                              std::to_string(static_cast<unsigned long>(n) * tokens_per_item) + " values, the file holds " +
                              std::to_string(left) + " more");
    return n;
  }
  /// Skips the remaining tokens of `line`.
  void skip_rest_of_line(size_t line) {
    while (!done() && tokens_[pos_].line == line) ++pos_;
  }

 private:
  std::string path_;
  std::vector<Token> tokens_;
  size_t pos_ = 0, last_line_ = 0;
};

Points to_points(const std::vector<Vec3>& v, double scale);
void check_indices(const std::string& path, const Eigen::MatrixXi& idx, long n, const char* what);
/// Fan-triangulates a polygon; fewer than 3 vertices is an error at `line`.
void add_polygon(std::vector<Eigen::Vector3i>& tris, const std::vector<int>& poly, const std::string& path, size_t line);
/// The surface of `verts` and `tris` scaled to metres, index-checked; require_faces is false only
/// for point clouds read from mesh formats.
SurfaceMesh finish(const std::string& path, const std::vector<Vec3>& verts, const std::vector<Eigen::Vector3i>& tris,
                   double scale, bool require_faces);
/// The body that OFF and ASCII PLY share: a line "x y z" per vertex (scaled by `inv`), then
/// "3 a b c" per triangle with 0-based indices.
void write_vertex_and_triangle_rows(std::ostream& out, const SurfaceMesh& m, double inv);

}  // namespace mesh_format
}  // namespace btr
