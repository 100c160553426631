"""The Python module as `cmake --install` leaves it: installed into a temporary prefix, the package
imports from PREFIX/PYTHON_DIR with nothing of the build tree on the path, reads its kernels from
PREFIX/share/tetrasand/shaders (not the build tree's) unless TETRASAND_SHADER_DIR says otherwise, and
samples a body.

Usage: installed_test.py CMAKE BUILD_DIR PYTHON_DIR MESH   (exit 0 when all holds)
"""
import os
import pathlib
import subprocess
import sys
import tempfile

CHECK = """
import os, pathlib, sys
import tetrasand
from tetrasand import _core
prefix = pathlib.Path(sys.argv[1]).resolve()
assert pathlib.Path(tetrasand.__file__).resolve().is_relative_to(prefix), tetrasand.__file__
root = pathlib.Path(_core._shader_root()).resolve()
assert root == prefix / "share" / "tetrasand" / "shaders", root
assert (root / "sdf").is_dir(), root
os.environ["TETRASAND_SHADER_DIR"] = "/elsewhere"
assert str(_core._shader_root()) == "/elsewhere"
body = tetrasand.sample(sys.argv[2], count=60, backend="cpu", sdf_backend="cpu")
assert body.count >= 60 and abs(body.mass - 1.0) < 1e-5, (body.count, body.mass)
print("installed module: kernels from", root, "and", body.count, "particles")
"""


def main():
    cmake, build, python_dir, mesh = sys.argv[1:5]
    with tempfile.TemporaryDirectory() as prefix:
        install = subprocess.run([cmake, "--install", build, "--prefix", prefix], capture_output=True, text=True)
        if install.returncode != 0:
            print(install.stdout, install.stderr, file=sys.stderr)
            return 1
        env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "TETRASAND_SHADER_DIR")}
        env["PYTHONPATH"] = str(pathlib.Path(prefix) / python_dir)
        run = subprocess.run([sys.executable, "-c", CHECK, prefix, mesh], env=env, cwd=prefix)
        return run.returncode


if __name__ == "__main__":
    sys.exit(main())
