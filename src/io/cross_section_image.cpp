#include "breast_tumour_registration/io/cross_section_image.h"

#include <cairo.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "breast_tumour_registration/base/errors.h"

namespace btr {
namespace {

using Seg = std::pair<Eigen::Vector2d, Eigen::Vector2d>;

// The segments where the plane y = y0 cuts the triangles, as (x, z) pairs.
std::vector<Seg> slice(const SurfaceMesh& s, double y0) {
  std::vector<Seg> out;
  for (Eigen::Index f = 0; f < s.F.rows(); ++f) {
    std::vector<Eigen::Vector2d> pts;
    for (int k = 0; k < 3; ++k) {
      const Vec3 a = s.V.row(s.F(f, k)), b = s.V.row(s.F(f, (k + 1) % 3));
      const double da = a.y() - y0, db = b.y() - y0;
      if ((da < 0) == (db < 0) || da == db) continue;
      const Vec3 p = a + (da / (da - db)) * (b - a);
      pts.emplace_back(p.x(), p.z());
    }
    if (pts.size() == 2) out.emplace_back(pts[0], pts[1]);
  }
  return out;
}

// A tick spacing of 1, 2 or 5 times a power of ten giving at most `most` intervals over `span`.
double tick_step(double span, int most) {
  const double raw = span / most, p = std::pow(10.0, std::floor(std::log10(raw)));
  for (double m : {1.0, 2.0, 5.0, 10.0})
    if (m * p >= raw) return m * p;
  return 10 * p;
}

void set_colour(cairo_t* cr, const std::array<unsigned char, 3>& c) { cairo_set_source_rgb(cr, c[0] / 255.0, c[1] / 255.0, c[2] / 255.0); }

void text_at(cairo_t* cr, const std::string& s, double x, double y, double align_x, double align_y) {
  cairo_text_extents_t e;
  cairo_text_extents(cr, s.c_str(), &e);
  cairo_move_to(cr, x - align_x * e.width - e.x_bearing, y - align_y * e.height - e.y_bearing);
  cairo_show_text(cr, s.c_str());
}

}  // namespace

void write_cross_section_png(const std::string& path, const std::vector<Outline>& outlines, double y0,
                             const std::string& title, int w, int h) {
  std::vector<std::vector<Seg>> segs;
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  for (const auto& o : outlines) {
    segs.push_back(slice(*o.surface, y0));
    for (const auto& s : segs.back())
      for (const auto& p : {s.first, s.second}) {
        lo = lo.cwiseMin(p * 1e3);
        hi = hi.cwiseMax(p * 1e3);
      }
  }
  if (!(hi.x() > lo.x())) throw InputError("cross section: no surface meets the plane y = " + std::to_string(y0));
  // Plot area in pixels: axes at the left and bottom, the legend at the right. Equal scales:
  // the image is cut to the plot's shape, within width x height.
  const double left = 70, legend = 290, top = 50, below = 60;
  const double pad = 0.04 * std::max(hi.x() - lo.x(), hi.y() - lo.y());
  lo.array() -= pad;
  hi.array() += pad;
  const double scale = std::min((w - left - legend) / (hi.x() - lo.x()), (h - top - below) / std::max(hi.y() - lo.y(), 1e-9));
  w = static_cast<int>(std::ceil(left + legend + (hi.x() - lo.x()) * scale));
  h = static_cast<int>(std::ceil(top + below + (hi.y() - lo.y()) * scale));
  const double bottom = h - below;
  auto px = [&](double x_mm) { return left + (x_mm - lo.x()) * scale; };
  auto py = [&](double z_mm) { return bottom - (z_mm - lo.y()) * scale; };
  const double plot_right = px(hi.x()), plot_top = py(hi.y());

  std::unique_ptr<cairo_surface_t, decltype(&cairo_surface_destroy)> surface(
      cairo_image_surface_create(CAIRO_FORMAT_RGB24, w, h), cairo_surface_destroy);
  std::unique_ptr<cairo_t, decltype(&cairo_destroy)> ctx(cairo_create(surface.get()), cairo_destroy);
  cairo_t* cr = ctx.get();
  cairo_set_source_rgb(cr, 1, 1, 1);
  cairo_paint(cr);
  cairo_select_font_face(cr, "DejaVu Sans", CAIRO_FONT_SLANT_NORMAL, CAIRO_FONT_WEIGHT_NORMAL);

  // Outlines, clipped to the plot area, in the order given (later ones on top).
  cairo_save(cr);
  cairo_rectangle(cr, left, plot_top, plot_right - left, bottom - plot_top);
  cairo_clip(cr);
  cairo_set_line_cap(cr, CAIRO_LINE_CAP_ROUND);
  for (size_t k = 0; k < outlines.size(); ++k) {
    for (const auto& s : segs[k]) {
      cairo_move_to(cr, px(s.first.x() * 1e3), py(s.first.y() * 1e3));
      cairo_line_to(cr, px(s.second.x() * 1e3), py(s.second.y() * 1e3));
    }
    set_colour(cr, outlines[k].colour);
    cairo_set_line_width(cr, outlines[k].width);
    cairo_stroke(cr);
  }
  cairo_restore(cr);

  // Axes: a frame with ticks and numbers in mm.
  cairo_set_source_rgb(cr, 0, 0, 0);
  cairo_set_line_width(cr, 1);
  cairo_rectangle(cr, left, plot_top, plot_right - left, bottom - plot_top);
  cairo_stroke(cr);
  cairo_set_font_size(cr, 12);
  char buf[64];
  const double sx = tick_step(hi.x() - lo.x(), 8), sz = tick_step(hi.y() - lo.y(), 6);
  for (double x = std::ceil(lo.x() / sx) * sx; x <= hi.x(); x += sx) {
    cairo_move_to(cr, px(x), bottom);
    cairo_line_to(cr, px(x), bottom + 5);
    std::snprintf(buf, sizeof buf, "%g", std::abs(x) < 1e-9 ? 0.0 : x);
    text_at(cr, buf, px(x), bottom + 8, 0.5, 0);
  }
  for (double z = std::ceil(lo.y() / sz) * sz; z <= hi.y(); z += sz) {
    cairo_move_to(cr, left - 5, py(z));
    cairo_line_to(cr, left, py(z));
    std::snprintf(buf, sizeof buf, "%g", std::abs(z) < 1e-9 ? 0.0 : z);
    text_at(cr, buf, left - 8, py(z), 1, 0.5);
  }
  cairo_stroke(cr);
  cairo_set_font_size(cr, 14);
  text_at(cr, "x [mm]", 0.5 * (left + plot_right), h - 12.0, 0.5, 1);
  cairo_save(cr);
  cairo_translate(cr, 18, 0.5 * (plot_top + bottom));
  cairo_rotate(cr, -M_PI / 2);
  text_at(cr, "z [mm]", 0, 0, 0.5, 0.5);
  cairo_restore(cr);
  cairo_set_font_size(cr, 15);
  text_at(cr, title, 0.5 * w, 16, 0.5, 0);

  // Legend: one entry per distinct label, in first-seen order.
  cairo_set_font_size(cr, 13);
  std::vector<std::string> seen;
  double ly = plot_top + 10;
  for (const auto& o : outlines) {
    if (o.label.empty() || std::find(seen.begin(), seen.end(), o.label) != seen.end()) continue;
    seen.push_back(o.label);
    set_colour(cr, o.colour);
    cairo_set_line_width(cr, o.width);
    cairo_move_to(cr, plot_right + 20, ly);
    cairo_line_to(cr, plot_right + 50, ly);
    cairo_stroke(cr);
    cairo_set_source_rgb(cr, 0, 0, 0);
    text_at(cr, o.label, plot_right + 58, ly, 0, 0.5);
    ly += 22;
  }

  cairo_surface_flush(surface.get());
  if (cairo_surface_write_to_png(surface.get(), path.c_str()) != CAIRO_STATUS_SUCCESS)
    throw InputError("cannot write '" + path + "'");
}

}  // namespace btr
