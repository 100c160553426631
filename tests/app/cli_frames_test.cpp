// `tetrasand frames DIR -o OUT`: a contact sheet when ffmpeg is absent or a .png is asked for, ffmpeg
// run on the frames when it is on PATH, and clear errors for a folder without frames.
#include <gtest/gtest.h>

#include <fmt/format.h>
#include <sys/stat.h>

#include <cstdlib>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "core/atomic_file.h"
#include "preview/image.h"
#include "tests/test_support.h"

namespace ts {
namespace {

std::string q(const std::filesystem::path& p) { return fmt::format("'{}'", p.string()); }

// Sets PATH for the commands a test runs, and puts it back.
class ScopedPath {
 public:
  explicit ScopedPath(const std::string& path) : old_(std::getenv("PATH") ? std::getenv("PATH") : "") {
    ::setenv("PATH", path.c_str(), 1);
  }
  ~ScopedPath() { ::setenv("PATH", old_.c_str(), 1); }

 private:
  std::string old_;
};

// Seven 40 x 30 frames, numbered as `sim` numbers them.
std::filesystem::path frames_folder() {
  const auto dir = test::temp_dir() / "run";
  std::filesystem::create_directories(dir);
  for (int i = 0; i < 7; ++i) {
    preview::Image image;
    image.width = 40;
    image.height = 30;
    image.rgba.assign(4 * 40 * 30, static_cast<std::uint8_t>(30 * i));
    preview::write_png(dir / fmt::format("frame_{:06d}.png", i), image);
  }
  return dir;
}

TEST(CliFrames, WithoutFfmpegAMovieBecomesAContactSheetAndSaysWhere) {
  const auto dir = frames_folder();
  std::string out;
  {
    const ScopedPath no_ffmpeg("/nonexistent");
    ASSERT_EQ(test::run_tetrasand(
                  "frames " + q(dir) + " -o " + q(dir / "movie.mp4") + " --tiles 4 --columns 2", &out),
              0)
        << out;
  }
  EXPECT_NE(out.find("ffmpeg not found on PATH"), std::string::npos) << out;
  EXPECT_NE(out.find((dir / "movie.png").string()), std::string::npos) << out;
  EXPECT_FALSE(std::filesystem::exists(dir / "movie.mp4"));
  const preview::Image sheet = preview::read_png(dir / "movie.png");
  EXPECT_EQ(sheet.width, 2 * 40);
  EXPECT_EQ(sheet.height, 2 * 30);
  // Frames 0, 2, 4, 6 of the seven: the last tile (bottom right) is frame 6's grey, 180.
  EXPECT_EQ(sheet.pixel(79, 59)[0], 180);
  EXPECT_EQ(sheet.pixel(39, 29)[0], 0);
}

TEST(CliFrames, PngOutputIsASheetShrunkToTheTileWidth) {
  const auto dir = frames_folder();
  std::string out;
  ASSERT_EQ(
      test::run_tetrasand("frames " + q(dir) + " -o " + q(dir / "sheet.png") + " --tile-width 20", &out), 0)
      << out;
  const preview::Image sheet = preview::read_png(dir / "sheet.png");
  EXPECT_EQ(sheet.width, 4 * 20);  // seven tiles, four to a row
  EXPECT_EQ(sheet.height, 2 * 15);
  EXPECT_NE(out.find("contact sheet of 7 of 7 frames"), std::string::npos) << out;
  // White pixels in the first tile (frame 0, black) are its label's digits.
  const auto lit = [](const preview::Image& image) {
    std::size_t n = 0;
    for (int y = 0; y < 15; ++y)
      for (int x = 0; x < 20; ++x) n += image.pixel(x, y)[0] == 255 ? 1 : 0;
    return n;
  };
  EXPECT_GT(lit(sheet), 0u);
  ASSERT_EQ(test::run_tetrasand(
                "frames " + q(dir) + " -o " + q(dir / "plain.png") + " --tile-width 20 --no-labels", &out),
            0)
      << out;
  EXPECT_EQ(lit(preview::read_png(dir / "plain.png")), 0u) << "no label with --no-labels";
  // --json: standard output is one object saying what was written.
  ASSERT_EQ(test::run_tetrasand("frames " + q(dir) + " -o " + q(dir / "j.png") + " --json 2>/dev/null | cat > " +
                                q(dir / "frames.json")),
            0);
  std::ifstream json_in(dir / "frames.json");
  const nlohmann::json report = nlohmann::json::parse(json_in, nullptr, false);
  ASSERT_FALSE(report.is_discarded()) << "standard output is not one JSON object";
  EXPECT_EQ(report.at("kind"), "contact sheet");
  EXPECT_EQ(report.at("frames"), 7);
  EXPECT_EQ(report.at("output"), (dir / "j.png").string());
}

TEST(CliFrames, FfmpegOnThePathMakesTheFilm) {
  const auto dir = frames_folder();
  const auto bin = dir.parent_path() / "bin";
  std::filesystem::create_directories(bin);
  // A stand-in for ffmpeg: records its arguments and writes its last one (the output).
  write_file_atomically(bin / "ffmpeg", "#!/bin/sh\necho \"$@\" > \"" + (bin / "args").string() +
                                            "\"\nfor last; do :; done\necho film > \"$last\"\n");
  ::chmod((bin / "ffmpeg").c_str(), 0755);
  std::string out;
  {
    const ScopedPath fake(bin.string() + ":/usr/bin:/bin");
    ASSERT_EQ(test::run_tetrasand("frames " + q(dir) + " -o " + q(dir / "movie.mp4") + " --fps 12", &out), 0)
        << out;
  }
  EXPECT_EQ(read_file(dir / "movie.mp4"), "film\n");
  const std::string args = read_file(bin / "args");
  EXPECT_NE(args.find("-framerate 12"), std::string::npos) << args;
  EXPECT_NE(args.find((dir / "frame_*.png").string()), std::string::npos) << args;
  EXPECT_NE(out.find("7 frames at 12 frames/s"), std::string::npos) << out;
}

TEST(CliFrames, MissingOrEmptyFolderAndBadOutputAreErrors) {
  const auto dir = test::temp_dir();
  std::string out;
  EXPECT_EQ(test::run_tetrasand("frames " + q(dir / "none") + " -o " + q(dir / "m.png"), &out), 1);
  EXPECT_NE(out.find("none: no such folder"), std::string::npos) << out;
  EXPECT_EQ(test::run_tetrasand("frames " + q(dir) + " -o " + q(dir / "m.png"), &out), 1);
  EXPECT_NE(out.find("holds no frame_NNNNNN.png"), std::string::npos) << out;
  EXPECT_EQ(test::run_tetrasand("frames " + q(dir) + " -o " + q(dir / "m.gif"), &out), 1);
  EXPECT_NE(out.find("must end in .mp4 (a film) or .png"), std::string::npos) << out;
  EXPECT_EQ(test::run_tetrasand("frames --help", &out), 0);
  EXPECT_NE(out.find("--fps"), std::string::npos) << out;
}

}  // namespace
}  // namespace ts
