#!/usr/bin/env python3
"""tetrasand as a C++ package, used the way another project uses it (examples/cpp/).

  package_test.py installed SOURCE BUILD [--cxx CXX] [--launcher CCACHE]
      `cmake --install BUILD` into a temporary prefix, examples/cpp configured against it with
      CMAKE_PREFIX_PATH (find_package(tetrasand)), built and run on assets/cube.obj: the body printed
      has particles and the cube's mass (0.1 m side: 1e-3 m^3 at 1000 kg/m^3 = 1 kg).
  package_test.py subdirectory SOURCE
      examples/cpp configured with TETRASAND_SOURCE_DIR (add_subdirectory): the configure succeeds,
      tetrasand's outputs stay under its own binary folder and its tests and benchmarks are left out.
  package_test.py readme SOURCE
      every line of README.md's "From C++" code blocks is in examples/cpp, so the README shows the code
      the installed-package test builds.
"""
import argparse
import pathlib
import re
import subprocess
import sys
import tempfile

CUBE_MASS_KG = 1.0
CUBE_VOLUME_M3 = 1e-3


def run(cmd, **kwargs):
    print("+", " ".join(str(c) for c in cmd), flush=True)
    done = subprocess.run([str(c) for c in cmd], text=True, capture_output=True, **kwargs)
    if done.returncode != 0:
        sys.exit(f"failed ({done.returncode}): {' '.join(map(str, cmd))}\n{done.stdout}\n{done.stderr}")
    return done.stdout


def installed(args):
    source = pathlib.Path(args.source)
    with tempfile.TemporaryDirectory(prefix="tetrasand-package-") as tmp:
        prefix = pathlib.Path(tmp) / "prefix"
        run(["cmake", "--install", args.build, "--prefix", prefix])
        for rel in ("include/tetrasand/tetrasand.h", "include/tetrasand/sampler/sample_mesh.h",
                    "include/tetrasand/shaders/common/params.h", "lib/cmake/tetrasand/tetrasandConfig.cmake",
                    "lib/cmake/tetrasand/tetrasandConfigVersion.cmake", "lib/libtetrasand_core.a"):
            if not (prefix / rel).is_file():
                sys.exit(f"the install has no {rel}")
        build = pathlib.Path(tmp) / "example"
        configure = ["cmake", "-S", source / "examples/cpp", "-B", build, f"-DCMAKE_PREFIX_PATH={prefix}",
                     "-DCMAKE_BUILD_TYPE=Release"]
        if args.cxx:
            configure.append(f"-DCMAKE_CXX_COMPILER={args.cxx}")
        if args.launcher:
            configure += [f"-DCMAKE_CXX_COMPILER_LAUNCHER={args.launcher}", f"-DCMAKE_C_COMPILER_LAUNCHER={args.launcher}"]
        run(configure)
        run(["cmake", "--build", build, "-j2"])
        out = run([build / "sample_mesh", source / "assets/cube.obj", "300"])
    print(out)
    check_body(out)


def figure(out, name):
    match = re.search(rf"^{name}: (\S+)", out, re.M)
    if not match:
        sys.exit(f"the example printed no '{name}:' line:\n{out}")
    return float(match.group(1))


def check_body(out):
    count, mass, volume = figure(out, "particles"), figure(out, "mass"), figure(out, "volume")
    if count <= 0:
        sys.exit(f"no particles: {count}")
    # The volume is exact (divergence theorem) over the vertices, which assimp reads in float: a
    # relative 1e-6 is that rounding, a wrong density or volume is far outside it.
    if abs(mass / CUBE_MASS_KG - 1) > 1e-6 or abs(volume / CUBE_VOLUME_M3 - 1) > 1e-6:
        sys.exit(f"cube mass {mass} kg, volume {volume} m^3; expected {CUBE_MASS_KG} kg, {CUBE_VOLUME_M3} m^3")


def subdirectory(args):
    source = pathlib.Path(args.source)
    with tempfile.TemporaryDirectory(prefix="tetrasand-subdir-") as tmp:
        build = pathlib.Path(tmp)
        run(["cmake", "-S", source / "examples/cpp", "-B", build, f"-DTETRASAND_SOURCE_DIR={source}"])
        ours = build / "tetrasand"
        # Paths from CMAKE_BINARY_DIR would have put these at the outer project's root.
        if not (ours / "CMakeFiles").is_dir() or (build / "share").exists() or (build / "bin").exists():
            sys.exit("tetrasand's build outputs are not under its own binary folder")
        if (ours / "tests").exists() or (ours / "bench").exists():
            sys.exit("tests or benchmarks configured in a project that only uses tetrasand")
        cache = (build / "CMakeCache.txt").read_text()
        if "TETRASAND_BUILD_TESTS:BOOL=OFF" not in cache:
            sys.exit("TETRASAND_BUILD_TESTS is not off under add_subdirectory")


def readme(args):
    source = pathlib.Path(args.source)
    text = (source / "README.md").read_text()
    section = re.search(r"^## From C\+\+\n(.*?)(?=^## )", text, re.M | re.S)
    if not section:
        sys.exit("README.md has no '## From C++' section")
    blocks = re.findall(r"```(?:cpp|cmake)\n(.*?)```", section.group(1), re.S)
    if not blocks:
        sys.exit("README.md's From C++ section has no cpp or cmake block")
    example = "\n".join((source / "examples/cpp" / f).read_text() for f in ("main.cpp", "CMakeLists.txt"))
    example_lines = {line.strip() for line in example.splitlines()}
    missing = [line for block in blocks for line in block.splitlines()
               if line.strip() and line.strip() != "..." and line.strip() not in example_lines]
    if missing:
        sys.exit("README.md's From C++ lines not in examples/cpp:\n" + "\n".join(missing))


def main():
    parser = argparse.ArgumentParser()
    parser.add_argument("mode", choices=["installed", "subdirectory", "readme"])
    parser.add_argument("source")
    parser.add_argument("build", nargs="?")
    parser.add_argument("--cxx")
    parser.add_argument("--launcher")
    args = parser.parse_args()
    {"installed": installed, "subdirectory": subdirectory, "readme": readme}[args.mode](args)
    print(f"package_test {args.mode}: ok")


if __name__ == "__main__":
    main()
