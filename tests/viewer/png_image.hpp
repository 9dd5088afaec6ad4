#pragma once
// A PNG read back for the screenshot tests (VTK's PNG reader): RGB pixels, row 0 at the bottom
// (VTK's image convention), and the questions the tests ask of a picture.

#include <cstdint>
#include <filesystem>
#include <vector>

namespace kerf::test {

struct PngImage {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb; ///< width x height x 3, row 0 at the bottom

  /// Reads `file` (fails the calling test's assertions through an exception on a bad file).
  static PngImage read(const std::filesystem::path& file);
  [[nodiscard]] const std::uint8_t* at(int x, int y) const { return &rgb[3 * (static_cast<std::size_t>(y) * width + x)]; }
  /// Not the background (the viewer's white).
  [[nodiscard]] bool foreground(int x, int y) const {
    const std::uint8_t* p = at(x, y);
    return !(p[0] == 255 && p[1] == 255 && p[2] == 255);
  }
  /// Largest difference of a channel between this pixel and the other image's.
  [[nodiscard]] int difference(const PngImage& other, int x, int y) const;
};

} // namespace kerf::test
