// Readers bounded before they read (issue 46): only regular files are read (a device, a FIFO or a
// directory is refused at once naming it), node trees are checked before assimp recurses through them,
// and an emitter whose lattice is not finite is refused before its loop. Each command runs under
// `timeout`, so a reader that blocks or loops again fails the test instead of hanging it.
#include <fmt/format.h>
#include <gtest/gtest.h>
#include <sys/stat.h>
#include <sys/wait.h>

#include <array>
#include <chrono>
#include <cstdio>
#include <filesystem>
#include <string>

#include "core/atomic_file.h"
#include "tests/scene_texts.h"
#include "tests/test_support.h"

namespace ts {
namespace {
namespace fs = std::filesystem;
using test::quoted;

constexpr int kKilled = 137;  // timeout -s KILL's exit status

// Runs tetrasand with `args`, killed after 60 s; the exit code, stdout+stderr in *output.
int run_bounded(const std::string& args, std::string* output) {
  const std::string cmd =
      std::string("timeout -s KILL 60 '") + TETRASAND_BINARY + "' " + args + " 2>&1 </dev/null";
  FILE* pipe = ::popen(cmd.c_str(), "r");
  if (!pipe) throw std::runtime_error("popen failed");
  std::array<char, 4096> buffer{};
  output->clear();
  for (std::size_t n = 0; (n = std::fread(buffer.data(), 1, buffer.size(), pipe)) > 0;)
    output->append(buffer.data(), n);
  const int status = ::pclose(pipe);
  return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
}

// `args` is refused with exit 1 naming `file` ("FILE: PROBLEM"), well before the time limit; the output.
std::string expect_refused(const std::string& args, const fs::path& file, const std::string& problem) {
  std::string out;
  const auto start = std::chrono::steady_clock::now();
  const int code = run_bounded(args, &out);
  const double seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_NE(code, kKilled) << args << ": still running after 60 s";
  EXPECT_EQ(code, 1) << args << "\n" << out;
  EXPECT_NE(out.find(file.string() + ": " + problem), std::string::npos) << args << "\n" << out;
  EXPECT_LT(seconds, 30.0) << args;
  return out;
}

// A glTF whose `depth` nodes each hold the next as their only child; the innermost names a triangle.
std::string deep_gltf(int depth) {
  // One triangle: three float positions (36 bytes), base64.
  std::string nodes;
  for (int i = 0; i < depth; ++i) {
    nodes += i + 1 < depth ? fmt::format("{{\"children\":[{}]}},", i + 1) : std::string("{\"mesh\":0}");
  }
  return R"({"asset":{"version":"2.0"},"scene":0,"scenes":[{"nodes":[0]}],"nodes":[)" + nodes +
         R"(],"meshes":[{"primitives":[{"attributes":{"POSITION":0}}]}],)"
         R"("accessors":[{"bufferView":0,"componentType":5126,"count":3,"type":"VEC3",)"
         R"("min":[0,0,0],"max":[1,1,0]}],"bufferViews":[{"buffer":0,"byteLength":36}],)"
         R"("buffers":[{"byteLength":36,"uri":"data:application/octet-stream;base64,)"
         R"(AAAAAAAAAAAAAAAAAACAPwAAAAAAAAAAAAAAAAAAgD8AAAAA"}]})";
}

// A Collada document whose `depth` <node> elements nest, the innermost holding a triangle.
std::string deep_collada(int depth) {
  std::string open, close;
  for (int i = 0; i < depth; ++i) {
    open += fmt::format("<node id=\"n{}\">", i);
    close += "</node>";
  }
  return R"(<?xml version="1.0" encoding="utf-8"?>
<COLLADA xmlns="http://www.collada.org/2005/11/COLLADASchema" version="1.4.1">
<library_geometries><geometry id="g"><mesh>
<source id="p"><float_array id="a" count="9">0 0 0 1 0 0 0 1 0</float_array>
<technique_common><accessor source="#a" count="3" stride="3"><param name="X" type="float"/>
<param name="Y" type="float"/><param name="Z" type="float"/></accessor></technique_common></source>
<vertices id="v"><input semantic="POSITION" source="#p"/></vertices>
<triangles count="1"><input semantic="VERTEX" source="#v" offset="0"/><p>0 1 2</p></triangles>
</mesh></geometry></library_geometries>
<library_visual_scenes><visual_scene id="s">)" +
         open + R"(<instance_geometry url="#g"/>)" + close + R"(</visual_scene></library_visual_scenes>
<scene><instance_visual_scene url="#s"/></scene></COLLADA>
)";
}

TEST(BoundedReaders, ANodeTreeFiftyThousandDeepIsRefusedBeforeAssimpReadsIt) {
  const fs::path dir = test::temp_dir();
  write_file_atomically(dir / "deep.gltf", deep_gltf(50000));
  write_file_atomically(dir / "deep.dae", deep_collada(50000));
  expect_refused("info " + quoted(dir / "deep.gltf"), dir / "deep.gltf",
                 "glTF: the node tree is 1001 levels deep");
  expect_refused("sdf " + quoted(dir / "deep.gltf") + " -o " + quoted(dir / "a.vdb"), dir / "deep.gltf",
                 "glTF: the node tree");
  expect_refused("info " + quoted(dir / "deep.dae"), dir / "deep.dae",
                 "<node> elements nest more than 1000 deep");
  expect_refused("sample " + quoted(dir / "deep.dae") + " -o " + quoted(dir / "out") + " --backend cpu",
                 dir / "deep.dae", "<node> elements nest");
  // The same trees, shallow, are read: the checks refuse depth, not the format.
  write_file_atomically(dir / "shallow.gltf", deep_gltf(20));
  write_file_atomically(dir / "shallow.dae", deep_collada(20));
  std::string out;
  EXPECT_EQ(run_bounded("info " + quoted(dir / "shallow.gltf"), &out), 0) << out;
  EXPECT_EQ(run_bounded("info " + quoted(dir / "shallow.dae"), &out), 0) << out;
}

TEST(BoundedReaders, DevicesFifosAndDirectoriesAreRefusedAtOnceNamingThem) {
  const fs::path dir = test::temp_dir();
  ASSERT_EQ(::mkfifo((dir / "pipe.obj").c_str(), 0600), 0);
  ASSERT_EQ(::mkfifo((dir / "pipe.toml").c_str(), 0600), 0);
  ASSERT_EQ(::mkfifo((dir / "pipe.vdb").c_str(), 0600), 0);
  ASSERT_EQ(::mkfifo((dir / "p.body.json").c_str(), 0600), 0);
  fs::create_directory(dir / "folder.obj");
  const fs::path zero = "/dev/zero";
  const std::string png = " -o " + quoted(dir / "x.png") + " --size 16x16 --resolution 8";
  const std::string sphere = quoted(test::asset("sphere.obj"));
  // Meshes.
  expect_refused("info " + quoted(zero), zero, "is a character device, not a regular file");
  expect_refused("info " + quoted(dir / "pipe.obj"), dir / "pipe.obj",
                 "is a FIFO (named pipe), not a regular file");
  expect_refused("info " + quoted(dir / "folder.obj"), dir / "folder.obj",
                 "is a directory, not a regular file");
  // Scenes.
  expect_refused("sim " + quoted(zero) + " -o " + quoted(dir / "o"), zero, "is a character device");
  expect_refused("sim " + quoted(dir / "pipe.toml") + " -o " + quoted(dir / "o"), dir / "pipe.toml",
                 "is a FIFO");
  expect_refused("export lammps " + quoted(dir / "pipe.toml") + " -o " + quoted(dir / "o"), dir / "pipe.toml",
                 "is a FIFO");
  // Level sets, particle files and bodies.
  expect_refused("preview " + quoted(dir / "pipe.vdb") + png, dir / "pipe.vdb", "is a FIFO");
  expect_refused("preview " + sphere + " --particles " + quoted(zero) + png, zero, "is a character device");
  expect_refused("preview " + sphere + " --particles " + quoted(dir / "p.body.json") + png,
                 dir / "p.body.json", "is a FIFO");
}

TEST(BoundedReaders, AnEmitterOfGrainsWithRadius1e308IsRefusedBeforeItsLattice) {
  const fs::path dir = test::temp_dir();
  std::string scene = std::string("gravity = [0.0, 0.0, -9.81]\n") + test::kMinimalScene;
  scene.replace(scene.find("radius = 1.0e-3"), 15, "radius = 1.0e308");
  const std::string column =
      scene + "[[emitter]]\ntype = \"column\"\ncentre = [0.0, 0.0, 0.0]\nradius = 0.01\ncount = 10\n";
  write_file_atomically(dir / "column.toml", column);
  const std::string out =
      expect_refused("sim " + quoted(dir / "column.toml") + " -o " + quoted(dir / "o") + " --backend cpu",
                     fs::path(dir / "column.toml:14"), "emitter: its largest grain");
  EXPECT_NE(out.find("lattice spacing"), std::string::npos) << out;
  const std::string fill = scene + test::box_emitter("fill", "[0.0, 0.0, 0.0]", "[0.1, 0.1, 0.1]", 10);
  write_file_atomically(dir / "fill.toml", fill);
  expect_refused("export lammps " + quoted(dir / "fill.toml") + " -o " + quoted(dir / "o"),
                 fs::path(dir / "fill.toml:14"), "emitter: its largest grain");
}

}  // namespace
}  // namespace ts
