#include "preview/frame_sheet.h"

#include <fmt/format.h>

#include <unistd.h>
#include <algorithm>
#include <array>
#include <charconv>
#include <cmath>

#include "core/error.h"

namespace ts::preview {
namespace fs = std::filesystem;

namespace {

// 3x5 digits, a row per entry, the top row first, bit 2 the left column.
constexpr std::array<std::array<std::uint8_t, 5>, 10> kDigits{{{7, 5, 5, 5, 7},
                                                               {2, 6, 2, 2, 7},
                                                               {7, 1, 7, 4, 7},
                                                               {7, 1, 7, 1, 7},
                                                               {5, 5, 7, 1, 1},
                                                               {7, 4, 7, 1, 7},
                                                               {7, 4, 7, 5, 7},
                                                               {7, 1, 1, 1, 1},
                                                               {7, 5, 7, 5, 7},
                                                               {7, 5, 7, 1, 7}}};

// NNNNNN of frame_NNNNNN.png, or none.
std::optional<std::int64_t> frame_number(const std::string& name) {
  constexpr std::string_view prefix = "frame_", suffix = ".png";
  if (name.size() <= prefix.size() + suffix.size() || !name.starts_with(prefix) || !name.ends_with(suffix))
    return std::nullopt;
  const std::string_view digits(name.data() + prefix.size(), name.size() - prefix.size() - suffix.size());
  if (!std::all_of(digits.begin(), digits.end(), [](char c) { return c >= '0' && c <= '9'; }))
    return std::nullopt;
  std::int64_t n = 0;
  if (std::from_chars(digits.data(), digits.data() + digits.size(), n).ec != std::errc()) return std::nullopt;
  return n;
}

}  // namespace

std::vector<FrameFile> list_frames(const fs::path& dir) {
  std::error_code ec;
  if (!fs::exists(dir, ec))
    throw InputError(dir, "no such folder (expected the output folder of `tetrasand sim`)");
  if (!fs::is_directory(dir, ec))
    throw InputError(dir, "is not a folder (expected the output folder of `tetrasand sim`)");
  std::vector<FrameFile> frames;
  for (const fs::directory_entry& entry : fs::directory_iterator(dir)) {
    if (!entry.is_regular_file()) continue;
    if (const auto n = frame_number(entry.path().filename().string())) frames.push_back({entry.path(), *n});
  }
  if (frames.empty()) {
    throw InputError(dir, "holds no frame_NNNNNN.png (a scene writes them with [output] frames = true)");
  }
  std::sort(frames.begin(), frames.end(),
            [](const FrameFile& a, const FrameFile& b) { return a.number < b.number; });
  return frames;
}

std::vector<std::size_t> evenly_chosen(std::size_t n, std::size_t count) {
  std::vector<std::size_t> out;
  if (n == 0 || count == 0) return out;
  if (n <= count) {
    for (std::size_t i = 0; i < n; ++i) out.push_back(i);
    return out;
  }
  if (count == 1) return {0};
  for (std::size_t k = 0; k < count; ++k) {
    const std::size_t i =
        static_cast<std::size_t>(std::llround(static_cast<double>(k) * (n - 1) / (count - 1)));
    if (out.empty() || out.back() != i) out.push_back(i);
  }
  return out;
}

Image shrink(const Image& image, int width) {
  if (width <= 0 || width >= image.width) return image;
  Image out;
  out.width = width;
  out.height =
      std::max(1, static_cast<int>(std::lround(static_cast<double>(image.height) * width / image.width)));
  out.alpha = image.alpha;
  out.rgba.resize(4 * static_cast<std::size_t>(out.width) * out.height);
  const double sx = static_cast<double>(image.width) / out.width,
               sy = static_cast<double>(image.height) / out.height;
  for (int y = 0; y < out.height; ++y) {
    const int y0 = static_cast<int>(y * sy), y1 = std::max(y0 + 1, static_cast<int>((y + 1) * sy));
    for (int x = 0; x < out.width; ++x) {
      const int x0 = static_cast<int>(x * sx), x1 = std::max(x0 + 1, static_cast<int>((x + 1) * sx));
      std::array<double, 4> sum{};
      for (int v = y0; v < std::min(y1, image.height); ++v)
        for (int u = x0; u < std::min(x1, image.width); ++u)
          for (int c = 0; c < 4; ++c) sum[c] += image.pixel(u, v)[c];
      const double n =
          static_cast<double>((std::min(y1, image.height) - y0) * (std::min(x1, image.width) - x0));
      for (int c = 0; c < 4; ++c) out.pixel(x, y)[c] = static_cast<std::uint8_t>(std::lround(sum[c] / n));
    }
  }
  return out;
}

void draw_label(Image& image, const std::string& text, int x, int y, int scale) {
  const int pad = scale, w = static_cast<int>(text.size()) * 4 * scale - scale + 2 * pad,
            h = 5 * scale + 2 * pad;
  for (int v = std::max(y, 0); v < std::min(y + h, image.height); ++v) {
    for (int u = std::max(x, 0); u < std::min(x + w, image.width); ++u) {
      std::uint8_t* p = image.pixel(u, v);
      for (int c = 0; c < 3; ++c) p[c] = static_cast<std::uint8_t>(p[c] * 0.35);
      p[3] = 255;
    }
  }
  for (std::size_t k = 0; k < text.size(); ++k) {
    if (text[k] < '0' || text[k] > '9') continue;
    const auto& glyph = kDigits[static_cast<std::size_t>(text[k] - '0')];
    for (int row = 0; row < 5; ++row) {
      for (int col = 0; col < 3; ++col) {
        if (!(glyph[row] & (4 >> col))) continue;
        for (int dy = 0; dy < scale; ++dy) {
          for (int dx = 0; dx < scale; ++dx) {
            const int u = x + pad + (static_cast<int>(k) * 4 + col) * scale + dx,
                      v = y + pad + row * scale + dy;
            if (u >= 0 && v >= 0 && u < image.width && v < image.height)
              std::fill_n(image.pixel(u, v), 4, 255);
          }
        }
      }
    }
  }
}

Image frame_sheet(const std::vector<FrameFile>& frames, const SheetSettings& settings, std::size_t* shown) {
  std::vector<Image> tiles;
  int width = 0, height = 0;
  for (const std::size_t i : evenly_chosen(frames.size(), settings.tiles)) {
    Image frame = read_png(frames[i].path);
    if (tiles.empty()) {
      width = frame.width;
      height = frame.height;
    } else if (frame.width != width || frame.height != height) {
      throw InputError(
          frames[i].path,
          fmt::format("is {} x {} pixels, the first frame {} x {}: a sheet needs frames of one size",
                      frame.width, frame.height, width, height));
    }
    Image tile = shrink(frame, settings.tile_width);
    tile.alpha = false;
    const int scale = std::max(1, tile.height / 60);
    if (settings.labels) draw_label(tile, std::to_string(frames[i].number), scale, scale, scale);
    tiles.push_back(std::move(tile));
  }
  if (shown) *shown = tiles.size();
  return contact_sheet(tiles, settings.columns);
}

std::optional<fs::path> find_program(const std::string& name, const std::string& path_variable) {
  std::size_t start = 0;
  while (start <= path_variable.size()) {
    const std::size_t end = std::min(path_variable.find(':', start), path_variable.size());
    const std::string folder = path_variable.substr(start, end - start);
    const fs::path candidate = fs::path(folder.empty() ? "." : folder) / name;
    std::error_code ec;
    if (fs::is_regular_file(candidate, ec) && ::access(candidate.c_str(), X_OK) == 0) return candidate;
    start = end + 1;
  }
  return std::nullopt;
}

}  // namespace ts::preview
