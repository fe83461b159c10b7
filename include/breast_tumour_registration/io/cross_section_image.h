// A picture of a registration for a person to look at: the outlines of several surfaces cut
// by a plane (like the thesis's Figure 5.14), with axes in millimetres, a title and a legend,
// drawn with cairo and saved as PNG.
#pragma once

#include <array>
#include <string>
#include <vector>

#include "breast_tumour_registration/base/types.h"

namespace btr {

struct Outline {
  const SurfaceMesh* surface;
  std::array<unsigned char, 3> colour;
  double width = 2;   ///< line width [px]
  std::string label;  ///< legend entry; outlines with the same label are listed once, an empty one not at all
};

/// Cuts every surface with the plane y = y0 [m] and draws the x-z outlines (x to the right,
/// z up, equal scales) in an image of at most `width` by `height` pixels, cut to the plot's
/// shape: axes with ticks in mm, `title` above, the legend at the right. Throws InputError if the file cannot be written or no outline
/// meets the plane.
void write_cross_section_png(const std::string& path, const std::vector<Outline>& outlines, double y0,
                             const std::string& title, int width = 1000, int height = 640);

}  // namespace btr
