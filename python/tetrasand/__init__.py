"""tetrasand from Python: meshes to SDFs and particle rigid bodies, and sand scenes run or stepped.

    import tetrasand
    body = tetrasand.sample("cube.obj", count=500, backend="cpu")
    field = tetrasand.sdf("cube.obj", resolution=32, backend="cpu")
    tetrasand.run_scene("pile.toml", "out")

Errors are tetrasand.InputError (a ValueError: bad files and values, with the command line's message),
tetrasand.GpuError and tetrasand.Error (RuntimeErrors).
"""
import os as _os

from . import _paths
from ._core import (Body, Error, Field, GpuError, InputError, Scene, load_body, run_scene, sample, sdf,
                    _set_shader_root)

# The kernels: TETRASAND_SHADER_DIR when set (the library reads it), else the shaders installed or
# built beside this package (_paths.py, written by python/CMakeLists.txt, has the relative path).
_set_shader_root(_os.path.normpath(_os.path.join(_os.path.dirname(__file__), _paths.SHADERS)))

__all__ = ["Body", "Error", "Field", "GpuError", "InputError", "Scene", "load_body", "run_scene", "sample", "sdf"]
