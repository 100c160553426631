// `tetrasand frames DIR -o OUT`: the PNG frames of a `tetrasand sim` run ([output] frames = true) as a
// film (OUT.mp4, through ffmpeg when it is on PATH) or as a contact sheet (OUT.png, or instead of the
// film when ffmpeg is not installed: Debian's package `ffmpeg`).
#include <fmt/format.h>
#include <nlohmann/json.hpp>
#include <spawn.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "app/commands.h"
#include "app/numeric_options.h"
#include "core/atomic_file.h"
#include "preview/frame_sheet.h"

extern char** environ;

namespace ts::app {
namespace {

namespace fs = std::filesystem;

struct Options {
  std::string dir;
  std::string output;
  double fps = 30;
  preview::SheetSettings sheet;
  bool json = false;
};

void add_options(CLI::App* cmd, Options& o) {
  cmd->add_option("DIR", o.dir, "Output folder of `tetrasand sim` holding frame_NNNNNN.png")->required();
  cmd->add_option(
         "-o,--output", o.output,
         "movie.mp4 (ffmpeg; a contact sheet movie.png instead when ffmpeg is not on PATH) or sheet.png")
      ->required();
  cmd->add_option("--fps", o.fps, "Frames per second of the film")->check(positive())->capture_default_str();
  cmd->add_option("--tiles", o.sheet.tiles, "Frames on a contact sheet, chosen evenly from first to last")
      ->check(CLI::Range(1, 400))
      ->capture_default_str();
  cmd->add_option("--columns", o.sheet.columns, "Tiles per row of a contact sheet")
      ->check(CLI::Range(1, 64))
      ->capture_default_str();
  cmd->add_option("--tile-width", o.sheet.tile_width, "Width of a contact sheet's tiles [pixels]")
      ->check(CLI::Range(16, 4096))
      ->capture_default_str();
  cmd->add_flag("!--no-labels", o.sheet.labels, "No frame numbers on a contact sheet's tiles");
  cmd->add_flag("--json", o.json, "Print what was written (file, kind, frames) as JSON instead of text");
}

// Runs ffmpeg on DIR/frame_*.png into `target` (written atomically); ts::Error when it fails.
void run_ffmpeg(const fs::path& ffmpeg, const Options& o, const fs::path& target) {
  write_atomically(target, [&](const fs::path& tmp) {
    const std::string pattern = (fs::path(o.dir) / "frame_*.png").string();
    const std::string fps = fmt::format("{}", o.fps);
    // Even sides for yuv420p, the pixel format every player reads.
    std::vector<std::string> args{ffmpeg.string(),
                                  "-hide_banner",
                                  "-loglevel",
                                  "error",
                                  "-y",
                                  "-framerate",
                                  fps,
                                  "-pattern_type",
                                  "glob",
                                  "-i",
                                  pattern,
                                  "-vf",
                                  "pad=ceil(iw/2)*2:ceil(ih/2)*2",
                                  "-c:v",
                                  "libx264",
                                  "-pix_fmt",
                                  "yuv420p",
                                  "-f",
                                  "mp4",
                                  tmp.string()};
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    pid_t pid = 0;
    if (posix_spawn(&pid, argv[0], nullptr, nullptr, argv.data(), environ) != 0)
      throw InputError(ffmpeg, "cannot be started");
    int status = 0;
    if (waitpid(pid, &status, 0) < 0 || !WIFEXITED(status) || WEXITSTATUS(status) != 0 || !fs::exists(tmp))
      throw InputError(fmt::format("ffmpeg failed on {} (exit status {}): see its message above", pattern,
                                   WIFEXITED(status) ? WEXITSTATUS(status) : -1));
  });
}

// What run_frames wrote: one line of text, or with --json one object.
void report(const Options& o, const std::string& text, const fs::path& file, const std::string& kind,
            std::size_t frames, std::size_t shown, const std::string& note) {
  if (!o.json) {
    fmt::print("{}\n", text);
    return;
  }
  const nlohmann::ordered_json out = {{"output", file.string()}, {"kind", kind}, {"frames", frames},
                                      {"shown", shown},          {"fps", kind == "film" ? nlohmann::ordered_json(o.fps) : nullptr},
                                      {"note", note.empty() ? nlohmann::ordered_json(nullptr) : nlohmann::ordered_json(note)}};
  fmt::print("{}\n", out.dump(2));
}

int run_frames(const Options& o, const GlobalOptions&) {
  const fs::path out(o.output);
  const std::string ext = out.extension().string();
  if (ext != ".mp4" && ext != ".png")
    throw InputError(fmt::format("-o {}: must end in .mp4 (a film) or .png (a contact sheet)", o.output));
  const std::vector<preview::FrameFile> frames = preview::list_frames(o.dir);
  if (ext == ".mp4") {
    const char* path = std::getenv("PATH");
    if (const auto ffmpeg = preview::find_program("ffmpeg", path ? path : "")) {
      run_ffmpeg(*ffmpeg, o, out);
      report(o, fmt::format("{}: {} frames at {} frames/s (ffmpeg: {})", out.string(), frames.size(), o.fps,
                            ffmpeg->string()),
             out, "film", frames.size(), frames.size(), "");
      return 0;
    }
  }
  const fs::path sheet = fs::path(out).replace_extension(".png");
  std::size_t shown = 0;
  const preview::Image image = preview::frame_sheet(frames, o.sheet, &shown);
  std::vector<fs::path> inputs;
  for (const auto& f : frames) inputs.push_back(f.path);
  preview::write_png(sheet, image, inputs);
  if (ext == ".mp4") {
    const std::string note = "ffmpeg not found on PATH (Debian: apt install ffmpeg): a contact sheet instead";
    report(o,
           fmt::format("ffmpeg not found on PATH (Debian: apt install ffmpeg): wrote a contact sheet of {} of {} "
                       "frames to {} instead",
                       shown, frames.size(), sheet.string()),
           sheet, "contact sheet", frames.size(), shown, note);
  } else {
    report(o, fmt::format("{}: contact sheet of {} of {} frames", sheet.string(), shown, frames.size()), sheet,
           "contact sheet", frames.size(), shown, "");
  }
  return 0;
}

}  // namespace

Runner add_frames_command(CLI::App& app, const GlobalOptions& global) {
  return add_command<Options>(app, global, "frames",
                              "Turn the PNG frames of a sim run into a film (ffmpeg) or a contact sheet",
                              run_frames, add_options);
}

}  // namespace ts::app
