#include "breast_tumour_registration/io/cross_section_image.h"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <fstream>

#include "breast_tumour_registration/base/errors.h"

namespace btr {
namespace {

void put_u32(std::vector<unsigned char>& v, uint32_t x) {
  for (int s = 24; s >= 0; s -= 8) v.push_back(static_cast<unsigned char>(x >> s));
}

void chunk(std::ofstream& out, const char* type, const std::vector<unsigned char>& data) {
  std::vector<unsigned char> buf;
  put_u32(buf, static_cast<uint32_t>(data.size()));
  buf.insert(buf.end(), type, type + 4);
  buf.insert(buf.end(), data.begin(), data.end());
  const uint32_t crc = crc32(0, buf.data() + 4, static_cast<uInt>(buf.size() - 4));
  put_u32(buf, crc);
  out.write(reinterpret_cast<const char*>(buf.data()), static_cast<std::streamsize>(buf.size()));
}

using Seg = std::pair<Eigen::Vector2d, Eigen::Vector2d>;

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

}  // namespace

void write_png(const std::string& path, int w, int h, const std::vector<unsigned char>& rgb) {
  std::ofstream out(path, std::ios::binary);
  if (!out) throw InputError("cannot write '" + path + "'");
  const unsigned char sig[8] = {137, 80, 78, 71, 13, 10, 26, 10};
  out.write(reinterpret_cast<const char*>(sig), 8);
  std::vector<unsigned char> ihdr;
  put_u32(ihdr, w);
  put_u32(ihdr, h);
  ihdr.insert(ihdr.end(), {8, 2, 0, 0, 0});  // 8-bit RGB
  chunk(out, "IHDR", ihdr);
  std::vector<unsigned char> raw;
  raw.reserve(static_cast<size_t>(h) * (3 * w + 1));
  for (int y = 0; y < h; ++y) {
    raw.push_back(0);  // filter: none
    raw.insert(raw.end(), rgb.begin() + static_cast<long>(y) * 3 * w, rgb.begin() + static_cast<long>(y + 1) * 3 * w);
  }
  uLongf len = compressBound(raw.size());
  std::vector<unsigned char> z(len);
  if (compress2(z.data(), &len, raw.data(), raw.size(), 6) != Z_OK) throw InputError("PNG compression failed");
  z.resize(len);
  chunk(out, "IDAT", z);
  chunk(out, "IEND", {});
}

void write_cross_section_png(const std::string& path, const std::vector<Outline>& outlines, double y0, int w, int h) {
  std::vector<std::vector<Seg>> segs;
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  for (const auto& o : outlines) {
    segs.push_back(slice(*o.surface, y0));
    for (const auto& s : segs.back())
      for (const auto& p : {s.first, s.second}) {
        lo = lo.cwiseMin(p);
        hi = hi.cwiseMax(p);
      }
  }
  if (!(hi.x() > lo.x())) throw InputError("cross section: no surface meets the plane y = " + std::to_string(y0));
  const double margin = 40;
  const double scale = std::min((w - 2 * margin) / (hi.x() - lo.x()), (h - 2 * margin) / std::max(hi.y() - lo.y(), 1e-9));
  std::vector<unsigned char> img(static_cast<size_t>(w) * h * 3, 24);
  auto plot = [&](double px, double py, const std::array<unsigned char, 3>& c, int width) {
    for (int dy = -width / 2; dy <= width / 2; ++dy)
      for (int dx = -width / 2; dx <= width / 2; ++dx) {
        const int x = static_cast<int>(std::lround(px)) + dx, y = static_cast<int>(std::lround(py)) + dy;
        if (x < 0 || y < 0 || x >= w || y >= h) continue;
        std::copy(c.begin(), c.end(), img.begin() + 3 * (static_cast<long>(y) * w + x));
      }
  };
  auto to_px = [&](const Eigen::Vector2d& p) {
    return Eigen::Vector2d(margin + (p.x() - lo.x()) * scale, h - margin - (p.y() - lo.y()) * scale);
  };
  auto line = [&](Eigen::Vector2d a, Eigen::Vector2d b, const std::array<unsigned char, 3>& c, int width) {
    const int n = std::max(1, static_cast<int>(std::ceil((b - a).norm())));
    for (int i = 0; i <= n; ++i) {
      const Eigen::Vector2d p = a + (b - a) * (static_cast<double>(i) / n);
      plot(p.x(), p.y(), c, width);
    }
  };
  for (size_t k = 0; k < outlines.size(); ++k)
    for (const auto& s : segs[k]) line(to_px(s.first), to_px(s.second), outlines[k].colour, outlines[k].width);
  // 10 mm scale bar.
  line(Eigen::Vector2d(margin, h - margin / 2), Eigen::Vector2d(margin + 0.010 * scale, h - margin / 2), {255, 255, 255}, 3);
  write_png(path, w, h, img);
}

}  // namespace btr
