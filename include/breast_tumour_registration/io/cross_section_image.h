// A picture of a registration for a person to look at: the outlines of several surfaces cut
// by a plane (like the thesis's Figure 5.14), drawn into an RGB image and saved as PNG.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "breast_tumour_registration/base/types.h"

namespace btr {

struct Outline {
  const SurfaceMesh* surface;
  std::array<unsigned char, 3> colour;
  int width = 2;  ///< line width [px]
};

/// Cuts every surface with the plane y = y0 and draws the x-z outlines (x to the right, z
/// up), fitted to a `width` by `height` image with a 10 mm scale bar in the lower left.
/// Throws InputError if the file cannot be written or no outline meets the plane.
void write_cross_section_png(const std::string& path, const std::vector<Outline>& outlines, double y0, int width = 900,
                             int height = 600);

/// Minimal PNG encoder (8-bit RGB, zlib-compressed). rgb holds width*height*3 bytes.
void write_png(const std::string& path, int width, int height, const std::vector<unsigned char>& rgb);

}  // namespace btr
