#pragma once
/// \file png.hpp
/// \brief A small RGB raster with a built-in 5×7 pixel font, and a PNG encoder for it.
///
/// Just enough to draw the quality histograms as PNG figures without a graphics library:
/// filled rectangles, lines and upper-case text. The encoder writes 8-bit RGB, no interlace,
/// filter type 0 on every row and zlib level 9, so the same image always gives the same
/// bytes (for a given zlib).

#include <cstdint>
#include <string>
#include <string_view>
#include <vector>

namespace isohex {

/// An 8-bit RGB colour.
struct Rgb {
  std::uint8_t r = 0, g = 0, b = 0;
  friend bool operator==(const Rgb&, const Rgb&) = default;
};

/// Parses "#rrggbb" (the colours the SVG figures use); throws std::invalid_argument otherwise.
Rgb rgb_from_hex(std::string_view hex);

/// A width × height RGB image, rows top to bottom. Drawing outside the image is clipped.
class RgbImage {
 public:
  RgbImage(int width, int height, Rgb background = {255, 255, 255});

  [[nodiscard]] int width() const { return width_; }
  [[nodiscard]] int height() const { return height_; }
  [[nodiscard]] Rgb at(int x, int y) const;
  void set(int x, int y, Rgb c);
  /// Fills [x0, x1) × [y0, y1).
  void fill_rect(int x0, int y0, int x1, int y1, Rgb c);
  /// One-pixel horizontal / vertical lines, both ends included.
  void hline(int x0, int x1, int y, Rgb c);
  void vline(int x, int y0, int y1, Rgb c);

  /// Text in the 5×7 font, each font pixel drawn as a scale × scale block; lower-case letters
  /// are drawn upper-case and characters without a glyph as '?'. (x, y) is the top left corner.
  void text(int x, int y, std::string_view s, Rgb c, int scale = 1);
  /// The drawn width of `s` in pixels (6 font pixels per character, the last column blank).
  static int text_width(std::string_view s, int scale = 1);
  /// Text drawn bottom-to-top (rotated 90° counter-clockwise), its top left corner at (x, y).
  void text_vertical(int x, int y, std::string_view s, Rgb c, int scale = 1);

  /// The packed RGB bytes, 3 per pixel, row by row.
  [[nodiscard]] const std::vector<std::uint8_t>& pixels() const { return pixels_; }

 private:
  int width_, height_;
  std::vector<std::uint8_t> pixels_;
};

/// True if the 5×7 font has a glyph for `c` (after upper-casing).
bool font_has_glyph(char c);

/// The image as a complete PNG file (signature, IHDR, one IDAT, IEND).
std::string encode_png(const RgbImage& image);

}  // namespace isohex
