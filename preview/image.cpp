// The one translation unit holding the stb_image_write and stb_image implementations.
#define STB_IMAGE_WRITE_IMPLEMENTATION
#define STB_IMAGE_IMPLEMENTATION
#define STBI_ONLY_PNG
#include <stb/stb_image.h>
#include <stb/stb_image_write.h>

#include "preview/image.h"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>

#include "core/atomic_file.h"
#include "core/error.h"

namespace ts::preview {

namespace {

void append_bytes(void* context, void* data, int size) {
  static_cast<std::string*>(context)->append(static_cast<const char*>(data), static_cast<std::size_t>(size));
}

}  // namespace

void write_png(const std::filesystem::path& path, const Image& image, const std::vector<std::filesystem::path>& inputs) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgba.size() != 4 * static_cast<std::size_t>(image.width) * static_cast<std::size_t>(image.height)) {
    throw InputError(path, "cannot write an empty or inconsistent image");
  }
  const int channels = image.alpha ? 4 : 3;
  std::vector<std::uint8_t> packed;
  const std::uint8_t* data = image.rgba.data();
  if (channels == 3) {
    packed.resize(3 * static_cast<std::size_t>(image.width) * image.height);
    for (std::size_t i = 0, n = packed.size() / 3; i < n; ++i) std::copy_n(&image.rgba[4 * i], 3, &packed[3 * i]);
    data = packed.data();
  }
  std::string bytes;
  if (!stbi_write_png_to_func(append_bytes, &bytes, image.width, image.height, channels, data, channels * image.width)) {
    throw InputError(path, "PNG encoding failed");
  }
  write_file_atomically(path, bytes, inputs);
}

Image read_png(const std::filesystem::path& path) {
  const std::string bytes = read_file(path);
  int w = 0, h = 0, channels = 0;
  stbi_uc* pixels = stbi_load_from_memory(reinterpret_cast<const stbi_uc*>(bytes.data()), static_cast<int>(bytes.size()),
                                          &w, &h, &channels, 4);
  if (!pixels) throw InputError(path, std::string("is not a readable PNG (") + stbi_failure_reason() + ")");
  Image image;
  image.width = w;
  image.height = h;
  image.alpha = channels == 4 || channels == 2;
  image.rgba.assign(pixels, pixels + 4 * static_cast<std::size_t>(w) * h);
  stbi_image_free(pixels);
  return image;
}

Image contact_sheet(const std::vector<Image>& images, int columns) {
  if (images.empty()) return {};
  const int w = images.front().width, h = images.front().height;
  const int n = static_cast<int>(images.size());
  const int cols = columns > 0 ? std::min(columns, n) : static_cast<int>(std::ceil(std::sqrt(static_cast<double>(n))));
  const int rows = (n + cols - 1) / cols;
  Image sheet;
  sheet.width = cols * w;
  sheet.height = rows * h;
  sheet.alpha = images.front().alpha;
  sheet.rgba.assign(4 * static_cast<std::size_t>(sheet.width) * sheet.height, sheet.alpha ? 0 : 255);
  for (int k = 0; k < n; ++k) {
    const Image& im = images[k];
    if (im.width != w || im.height != h) throw InputError("contact sheet: the images differ in size");
    const int x0 = (k % cols) * w, y0 = (k / cols) * h;
    for (int y = 0; y < h; ++y) std::copy_n(im.pixel(0, y), 4 * w, sheet.pixel(x0, y0 + y));
  }
  return sheet;
}

ImageDifference compare_images(const Image& a, const Image& b, int threshold) {
  if (a.width != b.width || a.height != b.height) throw InputError("compare_images: the images differ in size");
  ImageDifference d;
  const std::size_t pixels = static_cast<std::size_t>(a.width) * a.height;
  double sum = 0.0;
  std::size_t over = 0;
  for (std::size_t p = 0; p < pixels; ++p) {
    int worst = 0;
    for (int c = 0; c < 4; ++c) {
      const int diff = std::abs(int(a.rgba[4 * p + c]) - int(b.rgba[4 * p + c]));
      sum += diff;
      worst = std::max(worst, diff);
    }
    d.max_abs = std::max(d.max_abs, worst);
    over += worst > threshold ? 1 : 0;
  }
  d.mean_abs = pixels ? sum / (4.0 * static_cast<double>(pixels)) : 0.0;
  d.fraction_over = pixels ? static_cast<double>(over) / static_cast<double>(pixels) : 0.0;
  return d;
}

}  // namespace ts::preview
