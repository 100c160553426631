// Keyframed kinematic props: the interpolation itself, both steppers following it, and scene parsing.
#include "sim/keyframes.h"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "body/body_file.h"
#include "core/error.h"
#include "sim/cpu_stepper.h"
#include "sim/gpu_stepper.h"
#include "scene/scene.h"
#include "scene/scene_world.h"
#include "sim/world.h"
#include "tests/test_support.h"

namespace ts::sim {
using namespace ts::scene;  // these tests run whole scenes through the engine
namespace {

constexpr double kPi = std::numbers::pi;

Eigen::Quaterniond about_z(double angle) { return Eigen::Quaterniond(Eigen::AngleAxisd(angle, Eigen::Vector3d::UnitZ())); }

// Three keys: a move along x while turning 90 degrees about z, then a climb with no turn.
std::vector<Keyframe> three_keys() {
  return {{0.5, {0, 0, 0.1}, about_z(0.0)}, {1.5, {0.2, 0, 0.1}, about_z(kPi / 2)}, {2.0, {0.2, 0, 0.3}, about_z(kPi / 2)}};
}

double angle_between(const Eigen::Quaterniond& a, const Eigen::Quaterniond& b) { return a.angularDistance(b); }

TEST(Keyframes, PoseInterpolatesLinearlyAndSlerps) {
  const auto keys = three_keys();
  const KinematicState mid = sample_track(keys, 1.0);  // halfway through the first segment
  EXPECT_LT((mid.position - Eigen::Vector3d(0.1, 0, 0.1)).norm(), 1e-15);
  EXPECT_LT(angle_between(mid.orientation, about_z(kPi / 4)), 1e-12);
  EXPECT_LT((mid.linear_velocity - Eigen::Vector3d(0.2, 0, 0)).norm(), 1e-15);       // 0.2 m in 1 s
  EXPECT_LT((mid.angular_velocity - Eigen::Vector3d(0, 0, kPi / 2)).norm(), 1e-12);  // 90 degrees in 1 s
  const KinematicState climb = sample_track(keys, 1.75);
  EXPECT_LT((climb.position - Eigen::Vector3d(0.2, 0, 0.2)).norm(), 1e-15);
  EXPECT_LT((climb.linear_velocity - Eigen::Vector3d(0, 0, 0.4)).norm(), 1e-14);
  EXPECT_LT(climb.angular_velocity.norm(), 1e-12);
}

TEST(Keyframes, HoldsTheFirstPoseBeforeAndTheLastAfterAtRest) {
  const auto keys = three_keys();
  for (double t : {0.0, 0.49}) {
    const KinematicState s = sample_track(keys, t);
    EXPECT_EQ(s.position, keys.front().position);
    EXPECT_EQ(s.linear_velocity.norm() + s.angular_velocity.norm(), 0.0);
  }
  for (double t : {2.0, 7.0}) {
    const KinematicState s = sample_track(keys, t);
    EXPECT_EQ(s.position, keys.back().position);
    EXPECT_EQ(s.linear_velocity.norm() + s.angular_velocity.norm(), 0.0);
  }
}

// The velocities are the derivatives of the pose: a central difference of sampled poses matches them.
TEST(Keyframes, VelocitiesAreTheDerivativesOfThePose) {
  std::vector<Keyframe> keys = three_keys();
  keys[1].orientation = Eigen::Quaterniond(Eigen::AngleAxisd(2.0, Eigen::Vector3d(1, 2, 3).normalized()));
  const double h = 1e-6;
  for (double t : {0.7, 1.2, 1.9}) {
    const KinematicState s = sample_track(keys, t);
    const KinematicState before = sample_track(keys, t - h), after = sample_track(keys, t + h);
    EXPECT_LT((s.linear_velocity - (after.position - before.position) / (2 * h)).norm(), 1e-8) << t;
    // (q(t + h) q(t - h)^-1) is a turn by omega 2h.
    const Eigen::AngleAxisd turn(after.orientation * before.orientation.conjugate());
    EXPECT_LT((s.angular_velocity - turn.axis() * turn.angle() / (2 * h)).norm(), 1e-6) << t;
  }
}

// A keyframed kinematic body in a world of its own, stepped by the CPU reference and the GPU: at
// every sampled time its pose and velocities are the track's.
World tracked_world() {
  World w;
  w.materials = {Material{}};
  BodyDesc desc;
  desc.motion = MotionType::Kinematic;
  add_body(w, desc, {Eigen::Vector3d(0.01, 0, 0), Eigen::Vector3d(-0.01, 0, 0)}, {0.005, 0.005}, 0);
  w.tracks.push_back({0, three_keys()});
  apply_tracks(w, 0.0);
  return w;
}

// tolerance: m, m/s and rad/s; angle_tolerance: rad (the GPU's slerp uses float trigonometry, which
// llvmpipe evaluates to about 5e-6 rad, measured, in both precisions).
void expect_on_track(const World& w, double tolerance, double angle_tolerance, const char* who) {
  const KinematicState s = sample_track(three_keys(), w.time);
  EXPECT_LT((w.bodies.position[0] - s.position).norm(), tolerance) << who << " t = " << w.time;
  EXPECT_LT(angle_between(w.bodies.orientation[0], s.orientation), angle_tolerance) << who << " t = " << w.time;
  EXPECT_LT((w.bodies.linear_velocity[0] - s.linear_velocity).norm(), tolerance) << who << " t = " << w.time;
  EXPECT_LT((w.bodies.angular_velocity[0] - s.angular_velocity).norm(), 10 * tolerance) << who << " t = " << w.time;
}

TEST(Keyframes, CpuAndGpuBodiesFollowTheTrack) {
  StepSettings settings;
  settings.dt = 0.01;
  settings.check_energy = false;
  World cpu_world = tracked_world();
  CpuStepper cpu(cpu_world, settings);
  gpu::Context context;
  const World start = tracked_world();
  for (Precision precision : {Precision::Float, Precision::Double}) {
    GpuStepper gpu(context, start, settings, precision);
    World gpu_world = start;
    for (int sample = 0; sample < 6; ++sample) {  // t = 0.4 (before the first key) ... 2.4 (after the last)
      gpu.step(40);
      gpu.download(gpu_world);
      expect_on_track(gpu_world, precision == Precision::Double ? 1e-6 : 2e-6, 2e-5, "gpu");
    }
  }
  for (int sample = 0; sample < 6; ++sample) {
    for (int s = 0; s < 40; ++s) cpu.step(cpu_world);
    expect_on_track(cpu_world, 1e-12, 1e-12, "cpu");
  }
}

// A scene's [[prop.keyframes]] (mesh-frame poses) become a track of the centre of mass.
std::string keyframed_prop(const std::string& keys, const std::string& prop_extra = "motion = \"kinematic\"\n") {
  return R"([[material]]
name = "steel"
E = 1.0e7
nu = 0.3
restitution = 0.5
mu = 0.3
density = 7800.0

[grain]
radius = 5.0e-3
material = "steel"

[[prop]]
body = "../bodies/plate.body.json"
material = "steel"
)" + prop_extra + keys;
}

const char* kGoodKeys = R"(
[[prop.keyframes]]
time = 0.0
position = [0.0, 0.0, 0.05]

[[prop.keyframes]]
time = 0.5
position = [0.1, 0.0, 0.05]
orientation = [0.7071067811865476, 0.0, 0.0, 0.7071067811865476]
)";

std::string scene_error(const std::string& text) {
  try {
    parse_scene(text, test::asset("scenes/keyframes.toml"));
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(Keyframes, SceneKeyframesBecomeACentreOfMassTrack) {
  const Scene scene = parse_scene(keyframed_prop(kGoodKeys), test::asset("scenes/keyframes.toml"));
  ASSERT_EQ(scene.props.size(), 1u);
  ASSERT_EQ(scene.props[0].keyframes.size(), 2u);
  const World w = make_world(scene);
  ASSERT_EQ(w.tracks.size(), 1u);
  const body::ParticleBody body = body::read_body(scene.props[0].body_file, body::BodyKeys::Physical);
  const Keyframe& last = scene.props[0].keyframes[1];
  const KinematicState end = sample_track(w.tracks[0].keys, 0.5);
  EXPECT_LT((end.position - (last.position + last.orientation * body.center_of_mass)).norm(), 1e-12);
  EXPECT_LT(angle_between(end.orientation, last.orientation), 1e-12);
  // At t = 0 the body stands at the first key, moving with the first segment's velocities.
  const std::uint32_t b = w.tracks[0].body;
  EXPECT_LT((w.bodies.position[b] - (Eigen::Vector3d(0, 0, 0.05) + body.center_of_mass)).norm(), 1e-12);
  EXPECT_NEAR(w.bodies.angular_velocity[b].z(), (kPi / 2) / 0.5, 1e-9);
}

TEST(Keyframes, UnsortedTimesAreAnErrorNamingFileLineAndKey) {
  const std::string keys = R"(
[[prop.keyframes]]
time = 0.5
position = [0.0, 0.0, 0.05]

[[prop.keyframes]]
time = 0.2
position = [0.1, 0.0, 0.05]
)";
  const std::string e = scene_error(keyframed_prop(keys));
  EXPECT_NE(e.find("keyframes.toml:23: prop.keyframes[1].time: 0.2 s is not after the previous key's 0.5 s"),
            std::string::npos)
      << e;
}

TEST(Keyframes, BadKeyframeTablesAreErrors) {
  EXPECT_NE(scene_error(keyframed_prop(kGoodKeys, "motion = \"dynamic\"\n")).find("only a kinematic prop"),
            std::string::npos);
  EXPECT_NE(scene_error(keyframed_prop(kGoodKeys, "motion = \"kinematic\"\nvelocity = [1.0, 0.0, 0.0]\n"))
                .find("either keyframes or velocity"),
            std::string::npos);
  const std::string one = "\n[[prop.keyframes]]\ntime = 0.0\nposition = [0.0, 0.0, 0.0]\n";
  EXPECT_NE(scene_error(keyframed_prop(one)).find("at least two keys"), std::string::npos);
  const std::string typo = std::string(kGoodKeys) + "\n[[prop.keyframes]]\ntime = 0.9\nposition = [0.0, 0.0, 0.0]\nangle = 3\n";
  EXPECT_NE(scene_error(keyframed_prop(typo)).find("prop.keyframes[2].angle: unknown key"), std::string::npos)
      << scene_error(keyframed_prop(typo));
  const std::string no_position = "\n[[prop.keyframes]]\ntime = 0.0\n\n[[prop.keyframes]]\ntime = 1.0\nposition = [0.0, 0.0, 0.0]\n";
  EXPECT_NE(scene_error(keyframed_prop(no_position)).find("prop.keyframes[0].position: missing"), std::string::npos)
      << scene_error(keyframed_prop(no_position));
}

}  // namespace
}  // namespace ts::sim
