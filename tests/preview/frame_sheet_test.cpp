// The pieces of `tetrasand frames`: listing a run's frames, choosing them evenly, shrinking and
// labelling tiles, and finding ffmpeg on a PATH.
#include <gtest/gtest.h>

#include <sys/stat.h>

#include "core/atomic_file.h"
#include "preview/frame_sheet.h"
#include "tests/input_error.h"
#include "tests/test_support.h"

namespace ts::preview {
namespace {

Image filled(int w, int h, std::uint8_t value) {
  Image image;
  image.width = w;
  image.height = h;
  image.rgba.assign(4 * static_cast<std::size_t>(w) * h, value);
  return image;
}

TEST(FrameSheet, FramesAreChosenEvenlyWithTheFirstAndTheLast) {
  EXPECT_EQ(evenly_chosen(5, 12), (std::vector<std::size_t>{0, 1, 2, 3, 4}));
  EXPECT_EQ(evenly_chosen(101, 5), (std::vector<std::size_t>{0, 25, 50, 75, 100}));
  EXPECT_EQ(evenly_chosen(10, 1), (std::vector<std::size_t>{0}));
  EXPECT_TRUE(evenly_chosen(0, 4).empty());
}

TEST(FrameSheet, FramesAreListedByNumberAndOtherFilesIgnored) {
  const auto dir = test::temp_dir();
  for (const char* name : {"frame_000010.png", "frame_000002.png", "frame_x.png", "metrics.csv"})
    write_png(dir / name, filled(4, 3, 100));
  const auto frames = list_frames(dir);
  ASSERT_EQ(frames.size(), 2u);
  EXPECT_EQ(frames[0].number, 2);
  EXPECT_EQ(frames[1].number, 10);
}

TEST(FrameSheet, MissingOrEmptyFoldersAreRefusedByName) {
  const auto dir = test::temp_dir();
  EXPECT_NE(test::input_error([&] { list_frames(dir / "nope"); }).find("nope: no such folder"),
            std::string::npos);
  EXPECT_NE(test::input_error([&] { list_frames(dir); }).find("holds no frame_NNNNNN.png"),
            std::string::npos);
}

TEST(FrameSheet, ShrinkAveragesAndLabelsAreWhiteDigits) {
  Image image = filled(8, 4, 0);
  for (int y = 0; y < 4; ++y) image.pixel(1, y)[0] = 200;  // a red column
  const Image small = shrink(image, 4);
  EXPECT_EQ(small.width, 4);
  EXPECT_EQ(small.height, 2);
  EXPECT_EQ(small.pixel(0, 0)[0], 100);  // columns 0 and 1 averaged
  EXPECT_EQ(small.pixel(1, 0)[0], 0);
  Image tile = filled(40, 20, 128);
  draw_label(tile, "18", 0, 0, 2);
  int white = 0;
  for (int y = 0; y < tile.height; ++y)
    for (int x = 0; x < tile.width; ++x) white += tile.pixel(x, y)[0] == 255 ? 1 : 0;
  EXPECT_EQ(white, 4 * (8 + 13));  // "1" has 8 lit cells of 3x5, "8" 13, each 2x2 pixels
}

TEST(FrameSheet, FfmpegIsFoundOnlyWhereThePathSaysAndOnlyIfExecutable) {
  const auto dir = test::temp_dir();
  std::filesystem::create_directories(dir / "bin");
  write_file_atomically(dir / "bin" / "ffmpeg", "#!/bin/sh\n");
  EXPECT_FALSE(find_program("ffmpeg", (dir / "bin").string())) << "not executable yet";
  ::chmod((dir / "bin" / "ffmpeg").c_str(), 0755);
  EXPECT_EQ(find_program("ffmpeg", "/nonexistent:" + (dir / "bin").string()), dir / "bin" / "ffmpeg");
  EXPECT_FALSE(find_program("ffmpeg", "/nonexistent"));
  EXPECT_FALSE(find_program("ffmpeg", ""));
}

}  // namespace
}  // namespace ts::preview
