#pragma once
// The frames a `tetrasand sim` run wrote (DIR/frame_NNNNNN.png), for `tetrasand frames`: listing
// them, a labelled contact sheet of frames chosen evenly over the run, and the lookup of the ffmpeg
// executable that turns them into a film when it is installed.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <string>
#include <vector>

#include "preview/image.h"

namespace ts::preview {

struct FrameFile {
  std::filesystem::path path;
  std::int64_t number = 0;  // NNNNNN
};

// The frame_NNNNNN.png files of `dir`, by number. ts::InputError for a missing folder, a file that
// is not a folder, or a folder without frames.
std::vector<FrameFile> list_frames(const std::filesystem::path& dir);

// `count` indices spread evenly over 0 .. n - 1, the first and the last included (all when n <= count).
std::vector<std::size_t> evenly_chosen(std::size_t n, std::size_t count);

// The image scaled to `width` pixels (height by its aspect, at least 1), each pixel the mean of the
// source pixels it covers; unchanged when it is not wider.
Image shrink(const Image& image, int width);

// Writes `text` (digits and spaces; anything else as a space) in a 3x5-pixel font, `scale` pixels per font
// pixel, white on a dark strip, with its top left corner at (x, y).
void draw_label(Image& image, const std::string& text, int x, int y, int scale);

struct SheetSettings {
  std::size_t tiles = 12;  // frames on the sheet
  int columns = 4;         // tiles per row
  int tile_width = 320;    // pixels
  bool labels = true;      // each tile's frame number in its top left corner
};

// A contact sheet of `frames` chosen evenly, each shrunk to the tile width and labelled with its
// frame number (unless settings.labels is false). ts::InputError when the frames differ in size or one cannot
// be read.
Image frame_sheet(const std::vector<FrameFile>& frames, const SheetSettings& settings,
                  std::size_t* shown = nullptr);

// The executable `name` in the folders of `path_variable` (a PATH-style list), or none.
std::optional<std::filesystem::path> find_program(const std::string& name, const std::string& path_variable);

}  // namespace ts::preview
