// The frames of `tetrasand sim`: the [output.camera] and color_by keys, what a frame of the bundled
// prop_drop scene shows (grains filling the picture, the box's walls), and the default camera
// framing the grains again as they spread.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <algorithm>
#include <set>
#include <sstream>
#include <string>

#include "core/atomic_file.h"
#include "preview/image.h"
#include "preview/sim_frames.h"
#include "scene/scene.h"
#include "scene/scene_world.h"
#include "tests/input_error.h"
#include "tests/scene_texts.h"
#include "tests/test_support.h"

namespace ts {
namespace {

std::string q(const std::filesystem::path& p) { return fmt::format("'{}'", p.string()); }

gpu::Context& context() {
  static gpu::Context c;
  return c;
}

// kCoarseSand, a prop of the bundled cube, then `output` (its first line is line 17).
std::string scene_with_output(const std::string& output) {
  return fmt::format(
      "{}[[prop]]\nbody = \"{}\"\nposition = [0.0, 0.0, 0.3]\nmaterial = \"sand\"\nmotion = "
      "\"dynamic\"\n{}",
      test::kCoarseSand, test::asset("bodies/cube.body.json").string(), output);
}

scene::Scene parse(const std::string& text) { return scene::parse_scene(text, "frames.toml"); }

TEST(FrameSettings, CameraAndColorKeysAreRead) {
  const scene::Scene scene = parse(scene_with_output(R"([output]
frames = true
color_by = "speed"
[output.camera]
eye = [1.0, -2.0, 0.5]
target = [0.0, 0.0, 0.1]
up = [0.0, 0.0, 2.0]
fov = 40.0
size = [320, 200]
)"));
  const preview::FrameSettings s = preview::frame_settings(scene.output);
  EXPECT_EQ(s.color_by, scene::FrameColoring::Speed);
  ASSERT_TRUE(s.camera.eye && s.camera.target);
  EXPECT_EQ(*s.camera.eye, Eigen::Vector3d(1.0, -2.0, 0.5));
  EXPECT_EQ(*s.camera.target, Eigen::Vector3d(0.0, 0.0, 0.1));
  EXPECT_EQ(s.camera.up, Eigen::Vector3d::UnitZ());
  EXPECT_EQ(s.camera.fov, 40.0);
  EXPECT_EQ(s.camera.width, 320);
  EXPECT_EQ(s.camera.height, 200);
  EXPECT_EQ(s.camera.follow_prop, -1);
  for (const std::string follow : {"prop cube", "prop 0"}) {
    const scene::Scene f = parse(scene_with_output("[output.camera]\nfollow = \"" + follow + "\"\n"));
    EXPECT_EQ(f.output.camera.follow_prop, 0) << follow;
  }
  const scene::Scene plain = parse(test::kCoarseSand);
  EXPECT_EQ(plain.output.color_by, scene::FrameColoring::Sand);
  EXPECT_EQ(plain.output.camera.width, 960);
  EXPECT_EQ(plain.output.camera.height, 720);
  EXPECT_FALSE(plain.output.camera.eye);
}

TEST(FrameSettings, BadCameraAndColorValuesAreRefusedWithFileAndLine) {
  // Line 17 holds [output], line 18 [output.camera], line 19 the key under test.
  const auto error = [](const std::string& line) {
    return test::input_error([&] { parse(scene_with_output("[output]\n[output.camera]\n" + line + "\n")); });
  };
  EXPECT_NE(error("fov = 190.0").find("frames.toml:19: output.camera.fov: must be < 180 degrees (got 190)"),
            std::string::npos);
  EXPECT_NE(error("fov = 0.0").find("frames.toml:19: output.camera.fov: must be > 0"), std::string::npos);
  EXPECT_NE(error("size = [8, 600]")
                .find("frames.toml:19: output.camera.size: 8 x 600 pixels: each side must be 16 "
                      "to 8192 pixels"),
            std::string::npos);
  EXPECT_NE(error("size = [320.5, 200]").find("output.camera.size: must be [width, height] in pixels"),
            std::string::npos);
  EXPECT_NE(
      error("fvo = 40.0").find("frames.toml:19: output.camera.fvo: unknown key (did you mean \"fov\"?)"),
      std::string::npos);
  EXPECT_NE(error("eye = [1.0, 0.0, 0.0]")
                .find("frames.toml:19: output.camera.eye: a fixed camera needs both eye "
                      "and target"),
            std::string::npos);
  EXPECT_NE(
      error("eye = [0.0, 0.0, 1.0]\ntarget = [0.0, 0.0, 0.0]").find("output.camera.up: must not be parallel"),
      std::string::npos);
  EXPECT_NE(
      error("up = [0.0, 0.0, 0.0]").find("frames.toml:19: output.camera.up: must not be the zero vector"),
      std::string::npos);
  const std::string follow = error("follow = \"prop wedge\"");
  EXPECT_NE(follow.find("frames.toml:19: output.camera.follow: no [[prop]] \"wedge\" (have: \"prop cube\" or "
                        "\"prop 0\")"),
            std::string::npos)
      << follow;
  EXPECT_NE(error("follow = \"cube\"").find("is not \"scene\" or \"prop NAME\""), std::string::npos);
  const std::string color =
      test::input_error([&] { parse(scene_with_output("[output]\ncolor_by = \"speeed\"\n")); });
  EXPECT_NE(
      color.find("frames.toml:18: output.color_by: \"speeed\" is not one of: sand, height, speed, body"),
      std::string::npos)
      << color;
  const std::string table = test::input_error([&] { parse(scene_with_output("[output]\ncamera = 3\n")); });
  EXPECT_NE(table.find("frames.toml:18: output.camera: must be an [output.camera] table"), std::string::npos)
      << table;
}

// Sand-coloured pixels (warm: red well above blue), and pixels of the walls' outline colour.
struct PixelCounts {
  double grains = 0, walls = 0;  // shares of the image's pixels
};
PixelCounts count_pixels(const preview::Image& image) {
  const preview::WallStyle style;
  std::size_t grains = 0, walls = 0;
  for (int y = 0; y < image.height; ++y) {
    for (int x = 0; x < image.width; ++x) {
      const std::uint8_t* p = image.pixel(x, y);
      if (p[0] > p[2] + 25 && p[0] >= p[1]) ++grains;
      bool wall = true;
      for (int c = 0; c < 3; ++c) wall = wall && std::abs(p[c] - 255.0f * style.color[c]) < 10.0f;
      walls += wall ? 1 : 0;
    }
  }
  const double n = static_cast<double>(image.width) * image.height;
  return {static_cast<double>(grains) / n, static_cast<double>(walls) / n};
}

// The bundled scene with frames on, small, through `tetrasand sim` on the CPU reference as a user runs
// it, for kSettledSeconds: with the default camera the grains fill more than a fifth of the picture and
// the box's walls show, in the first frame (the fill's tall block of grains) and in every frame once the
// bed has settled under the cube (the camera then frames the shallow bed, the cube sitting in it).
constexpr double kSettledFrom = 0.35;     // s: the grains have fallen (0.2 s) and the cube landed (0.26 s)
constexpr double kSettledSeconds = 0.45;  // s, the run's length
TEST(SimFrames, PropDropFramesAreMostlyGrainsAndShowTheWallsFirstAndSettled) {
  const auto dir = test::temp_dir();
  std::string text = read_file(test::asset("scenes/prop_drop.toml"));
  const std::string body = "\"../bodies/cube.body.json\"";
  text.replace(text.find(body), body.size(), "\"" + test::asset("bodies/cube.body.json").string() + "\"");
  text.replace(text.find("ply = true"), 10, "frames = true\n[output.camera]\nsize = [160, 120]\n");
  write_file_atomically(dir / "drop.toml", text);
  std::string out;
  ASSERT_EQ(test::run_tetrasand(fmt::format("sim {} -o {} --backend cpu --duration {}", q(dir / "drop.toml"),
                                            q(dir / "out"), kSettledSeconds),
                                &out),
            0)
      << out;
  // Frame k is metrics.csv's row k; its second column is the time (s).
  std::vector<double> times;
  std::istringstream metrics(read_file(dir / "out" / "metrics.csv"));
  std::string line;
  std::getline(metrics, line);  // the header
  while (std::getline(metrics, line)) times.push_back(std::stod(line.substr(line.find(',') + 1)));
  ASSERT_GE(times.size(), 3u) << out;
  std::size_t settled = 0;
  for (std::size_t frame = 0; frame < times.size(); ++frame) {
    const double t = times[frame];
    if (frame != 0 && t < kSettledFrom) continue;
    settled += frame != 0 ? 1 : 0;
    const auto path = dir / "out" / fmt::format("frame_{:06d}.png", frame);
    const preview::Image image = preview::read_png(path);
    ASSERT_EQ(image.width, 160);
    ASSERT_EQ(image.height, 120);
    const PixelCounts counts = count_pixels(image);
    EXPECT_GT(counts.grains, 0.2) << path.filename() << " (t = " << t
                                  << " s): grains should fill more than a "
                                  << "fifth of the frame";
    EXPECT_GT(counts.walls, 0.01) << path.filename() << ": the box's outline should show";
  }
  EXPECT_GE(settled, 2u) << "the run should reach the settled bed";
}

// A grain-only scene without walls: the default camera moves out at once when the grains spread, and
// back in slowly (a film does not jump) once they gather again.
TEST(SimFrames, DefaultCameraFramesTheGrainsAgainWhenTheySpread) {
  const auto dir = test::temp_dir();
  const scene::Scene scene =
      parse(std::string(test::kCoarseSand) +
            test::box_emitter("fill", "[-0.06, -0.06, 0.0]", "[0.06, 0.06, 0.06]", 20, "seed = 3\n"));
  sim::World world = scene::make_world(scene);
  preview::FrameSettings settings;
  settings.camera.width = 64;
  settings.camera.height = 48;
  preview::SimFrameWriter writer(context(), scene, settings);
  const auto distance = [&] { return (writer.camera().eye - writer.camera().target).norm(); };
  writer.write(world, 0, dir);
  const double close = distance();
  const std::vector<Eigen::Vector3d> gathered = world.bodies.position;
  for (Eigen::Vector3d& p : world.bodies.position) p *= 5.0;  // spread about the origin
  writer.write(world, 1, dir);
  const double spread = distance();
  EXPECT_GT(spread, 3.0 * close);
  for (const Eigen::Vector3d& p : world.bodies.position) {
    EXPECT_TRUE((p.array() >= writer.framed_box()->min.array()).all() &&
                (p.array() <= writer.framed_box()->max.array()).all());
  }
  world.bodies.position = gathered;
  writer.write(world, 2, dir);
  EXPECT_GT(distance(), 0.8 * spread) << "the camera should come back slowly";
  EXPECT_LT(distance(), spread);
  for (int frame = 3; frame < 80; ++frame) writer.write(world, frame, dir);
  EXPECT_LT(distance(), 1.1 * close) << "and end framing the gathered grains";
}

// follow = "prop cube": the camera looks at the prop's centre of mass wherever it goes, from the same
// distance.
TEST(SimFrames, FollowedPropStaysAtTheImageCentre) {
  const auto dir = test::temp_dir();
  const scene::Scene scene = parse(scene_with_output(
      test::box_emitter("fill", "[-0.06, -0.06, 0.0]", "[0.06, 0.06, 0.06]", 20, "seed = 3\n") +
      "[output]\nframes = true\n[output.camera]\nfollow = \"prop cube\"\nsize = [64, 48]\n"));
  sim::World world = scene::make_world(scene);
  preview::SimFrameWriter writer(context(), scene);
  writer.write(world, 0, dir);
  EXPECT_TRUE(writer.camera().target.isApprox(world.bodies.position[0]));  // the prop is the first body
  const double distance = (writer.camera().eye - writer.camera().target).norm();
  world.bodies.position[0] += Eigen::Vector3d(0.5, -0.2, 0.1);
  writer.write(world, 1, dir);
  EXPECT_TRUE(writer.camera().target.isApprox(world.bodies.position[0]));
  EXPECT_NEAR((writer.camera().eye - writer.camera().target).norm(), distance, 1e-9);
}

// Every colouring draws the grains; a fixed camera stays where the scene puts it.
TEST(SimFrames, ColoringsAndAFixedCameraRender) {
  const auto dir = test::temp_dir();
  scene::Scene scene =
      parse(std::string(test::kCoarseSand) +
            test::box_emitter("fill", "[-0.06, -0.06, 0.0]", "[0.06, 0.06, 0.06]", 20, "seed = 3\n") +
            "[[boundary]]\ntype = \"box\"\nmin = [-0.07, -0.07, 0.0]\nmax = [0.07, 0.07, 0.1]\n"
            "material = \"sand\"\n");
  sim::World world = scene::make_world(scene);
  for (std::size_t b = 0; b < world.bodies.size(); ++b)
    world.bodies.linear_velocity[b] = {0.0, 0.0, -0.05 * b};
  std::vector<std::uint32_t> first_colors;
  for (const auto color_by : {scene::FrameColoring::Sand, scene::FrameColoring::Height, scene::FrameColoring::Speed,
                              scene::FrameColoring::Body}) {
    scene.output.color_by = color_by;
    scene.output.camera.width = 64;
    scene.output.camera.height = 48;
    scene.output.camera.eye = Eigen::Vector3d(0.3, -0.3, 0.2);
    scene.output.camera.target = Eigen::Vector3d(0.0, 0.0, 0.01);
    preview::SimFrameWriter writer(context(), scene);
    const preview::Particles particles = writer.particles_of(world);
    ASSERT_EQ(particles.colors.size(), world.particles.size());
    // The colours vary over the grains (by shade, height, speed or body).
    EXPECT_GT(std::set<std::uint32_t>(particles.colors.begin(), particles.colors.end()).size(), 5u);
    writer.write(world, 0, dir);
    EXPECT_EQ(writer.camera().eye, Eigen::Vector3d(0.3, -0.3, 0.2));
    const preview::Image frame = preview::read_png(dir / "frame_000000.png");
    EXPECT_EQ(frame.width, 64);
    EXPECT_GT(count_pixels(frame).walls, 0.0) << static_cast<int>(color_by);
  }
}

}  // namespace
}  // namespace ts

namespace ts {
namespace {

// color_by = "body" colours a breakable prop's spheres by fragment: the whole ball one colour while its
// bonds hold, and once the bonds of one sphere break, that sphere a colour of its own (issue 48).
TEST(SimFrames, BodyColouringGivesEachFragmentOfABreakablePropOneColour) {
  const scene::Scene scene = scene::load_scene(test::asset("scenes/crumble.toml"));
  sim::World world = scene::make_world(scene);
  const std::vector<scene::BodyRange> ranges = scene::prop_body_ranges(scene, world);
  const std::uint32_t first = world.bodies.first_particle[ranges[0].first];
  const std::uint32_t end = first + ranges[0].count;
  preview::SimFrameWriter writer(context(), scene);
  const preview::Particles whole = writer.particles_of(world);
  for (std::uint32_t i = first; i < end; ++i) ASSERT_EQ(whole.colors[i], whole.colors[first]) << i;
  // Free the ball's last sphere: every bond it has breaks.
  const std::uint32_t freed = end - 1;
  for (std::size_t k = 0; k < world.bonds.size(); ++k) {
    if (world.bonds.a[k] == freed || world.bonds.b[k] == freed) world.bonds.intact[k] = 0;
  }
  const preview::Particles apart = writer.particles_of(world);
  EXPECT_NE(apart.colors[freed], apart.colors[first]);
  for (std::uint32_t i = first; i < freed; ++i) ASSERT_EQ(apart.colors[i], apart.colors[first]) << i;
}

}  // namespace
}  // namespace ts
