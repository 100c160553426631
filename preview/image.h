#pragma once
// 8-bit RGBA images, PNG files (stb_image_write / stb_image, written atomically) and contact sheets.
#include <cstdint>
#include <filesystem>
#include <vector>

namespace ts::preview {

struct Image {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgba;  // 4 bytes per pixel, top row first
  bool alpha = false;              // the alpha channel carries information (PNG RGBA, else RGB)

  std::uint8_t* pixel(int x, int y) { return rgba.data() + 4 * (static_cast<std::size_t>(y) * width + x); }
  const std::uint8_t* pixel(int x, int y) const {
    return rgba.data() + 4 * (static_cast<std::size_t>(y) * width + x);
  }
};

// Writes `image` as a PNG, atomically (temporary file + rename); refuses to overwrite any of `inputs`.
void write_png(const std::filesystem::path& path, const Image& image,
               const std::vector<std::filesystem::path>& inputs = {});

// Reads a PNG (or any format stb_image reads) as RGBA; ts::InputError naming the file otherwise.
Image read_png(const std::filesystem::path& path);

// Tiles equally sized images row by row, `columns` per row (0: the smallest square grid); empty
// cells are transparent when the images carry alpha, else white.
Image contact_sheet(const std::vector<Image>& images, int columns = 0);

// Per-channel comparison of two images of equal size, for golden-image tests.
struct ImageDifference {
  double mean_abs = 0.0;           // mean |a - b| over all channels, in 0..255
  double fraction_over = 0.0;      // fraction of pixels with some channel differing by more than `threshold`
  int max_abs = 0;
};
ImageDifference compare_images(const Image& a, const Image& b, int threshold = 24);

}  // namespace ts::preview
