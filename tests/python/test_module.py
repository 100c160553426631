"""The Python module `tetrasand` (python/): a path and numpy arrays in; bodies, fields and a short scene
out; errors as exceptions with the command line's messages. Small counts on the CPU paths (the tests
run on two cores). Run by ctest (Python.Module) with PYTHONPATH=<build>/python."""
import csv
import math
import os
import pathlib
import subprocess
import sys
import tempfile
import unittest

import numpy as np

import tetrasand

ROOT = pathlib.Path(__file__).resolve().parents[2]
CUBE = ROOT / "assets" / "cube.obj"          # side 0.1 m, centred at the origin
SPHERE = ROOT / "assets" / "sphere.obj"      # icosphere, radius 0.05 m
COLLISION = ROOT / "assets" / "scenes" / "two_grain_collision.toml"
PILE = ROOT / "assets" / "scenes" / "pile.toml"               # a pour emitter onto a rough floor


def obj_arrays(path):
    """The vertices and faces of a small OBJ file (v and f lines only) as numpy arrays."""
    vertices, faces = [], []
    for line in path.read_text().splitlines():
        parts = line.split()
        if parts[:1] == ["v"]:
            vertices.append([float(x) for x in parts[1:4]])
        elif parts[:1] == ["f"]:
            faces.append([int(x.split("/")[0]) - 1 for x in parts[1:4]])
    return np.array(vertices), np.array(faces)


def cube_distance(points, half=0.05):
    """The exact signed distance to the cube [-half, half]^3."""
    q = np.abs(points) - half
    outside = np.linalg.norm(np.maximum(q, 0.0), axis=1)
    inside = np.minimum(q.max(axis=1), 0.0)
    return outside + inside


class SampleTest(unittest.TestCase):
    def test_a_path_gives_the_count_asked_for_and_the_cube_mass(self):
        body = tetrasand.sample(str(CUBE), count=150, density=1000.0, backend="cpu", sdf_backend="cpu")
        self.assertEqual(body.positions.shape[1], 3)
        # The count sets the radius; the repair rounds may add particles, never remove the surface's.
        self.assertGreaterEqual(body.count, 150)
        self.assertLess(body.count, 300)
        self.assertEqual(body.positions.shape, (body.count, 3))
        # The mesh's coordinates come through assimp in single precision: 1e-6 relative.
        self.assertAlmostEqual(body.volume / 1e-3, 1.0, delta=1e-6)
        self.assertAlmostEqual(body.mass, 1.0, delta=1e-6)
        np.testing.assert_allclose(body.center_of_mass, [0.0, 0.0, 0.0], atol=1e-9)
        # A cube's inertia about its centre: m s^2 / 6 on the diagonal.
        np.testing.assert_allclose(body.inertia, np.eye(3) * 1.0 * 0.01 / 6.0, rtol=1e-5, atol=1e-12)
        np.testing.assert_allclose(body.principal_moments, [0.01 / 6.0] * 3, rtol=1e-5)
        self.assertEqual(body.principal_axes.shape, (3, 3))
        self.assertIn(body.verdict, ("body OK", "usable with caveats", "not usable"))
        self.assertTrue(body.verdict_reasons)
        self.assertIsInstance(body.coverage_certified, bool)
        self.assertGreater(body.covering_bound_over_r, 0.0)
        # Every particle lies on the cube's surface (the sampler projects them exactly).
        self.assertLess(np.abs(cube_distance(body.positions)).max(), 1e-3 * body.radius + 1e-7)

    def test_numpy_arrays_give_the_sphere_volume_times_density(self):
        vertices, faces = obj_arrays(SPHERE)
        body = tetrasand.sample((vertices, faces), count=100, density=2000.0, backend="cpu", sdf_backend="cpu")
        analytic = 4.0 / 3.0 * math.pi * 0.05**3
        self.assertAlmostEqual(body.volume / analytic, 1.0, delta=0.01)  # the icosphere is inscribed
        self.assertAlmostEqual(body.mass, body.volume * 2000.0, delta=1e-12)
        self.assertEqual(body.source_path, "<arrays>")
        radii = np.linalg.norm(body.positions, axis=1)
        self.assertLess(np.abs(radii - 0.05).max(), 0.001)

    def test_a_saved_body_reads_back_with_the_same_particles_and_mass(self):
        body = tetrasand.sample(str(CUBE), count=100, backend="cpu", sdf_backend="cpu", seed=3)
        with tempfile.TemporaryDirectory() as out:
            json_path = body.save(out, "cube")
            self.assertEqual(pathlib.Path(json_path).name, "cube.body.json")
            self.assertTrue((pathlib.Path(out) / "cube.particles.ply").is_file())
            back = tetrasand.load_body(json_path)
        np.testing.assert_allclose(back.positions, body.positions, atol=1e-7)
        self.assertEqual(back.mass, body.mass)
        self.assertEqual(back.radius, body.radius)
        self.assertEqual(back.covering_bound_over_r, body.covering_bound_over_r)

    def test_the_progress_callback_hears_the_relaxation(self):
        heard = []
        tetrasand.sample(str(CUBE), count=100, backend="cpu", sdf_backend="cpu", progress=heard.append)
        self.assertTrue(heard)
        self.assertEqual(set(heard[0]), {"round", "iteration", "particles", "residual"})


class SdfTest(unittest.TestCase):
    @classmethod
    def setUpClass(cls):
        cls.field = tetrasand.sdf(str(CUBE), resolution=32, band=3, backend="cpu")

    def test_band_voxels_hold_the_exact_distance_of_the_cube(self):
        f = self.field
        self.assertEqual(f.coords.shape, (f.values.shape[0], 3))
        self.assertGreater(f.values.shape[0], 1000)
        centres = f.origin + f.voxel_size * f.coords
        np.testing.assert_allclose(f.values, cube_distance(centres), atol=1e-6)
        self.assertLessEqual(np.abs(f.values).max(), 3 * f.voxel_size * (1 + 1e-6))

    def test_samples_have_the_sign_and_distance_at_known_points(self):
        f = self.field
        h = f.voxel_size
        points = np.array([[0.05 + h, 0.0, 0.0], [0.0, 0.05 - h, 0.0], [0.0, 0.0, 0.0], [0.3, 0.0, 0.0]])
        d = f.sample(points)
        self.assertAlmostEqual(d[0], h, delta=1e-6)      # outside, one voxel from the +x face
        self.assertAlmostEqual(d[1], -h, delta=1e-6)     # inside, one voxel from the +y face
        self.assertLess(d[2], 0.0)                        # deep inside: the negative background
        self.assertGreater(d[3], 0.0)                     # far outside: the positive background

    def test_the_gpu_scan_finds_its_kernels_and_agrees_with_the_exact_field(self):
        # The kernels are found from the package's folder (python/tetrasand/__init__.py), not beside an
        # executable; on llvmpipe the GL path runs on the CPU all the same.
        gpu = tetrasand.sdf(str(CUBE), resolution=16, band=2, backend="gpu")
        cpu = tetrasand.sdf(str(CUBE), resolution=16, band=2, backend="cpu")
        points = np.array([[0.05 + 0.5 * gpu.voxel_size, 0.01, -0.02], [0.0, 0.0, 0.05 - gpu.voxel_size]])
        np.testing.assert_allclose(gpu.sample(points), cpu.sample(points), atol=0.05 * gpu.voxel_size)

    def test_an_open_mesh_gets_the_commands_warning_about_its_signs(self):
        # The library logs on standard error (the process's, not sys.stderr): a child process shows it.
        code = ("import sys, tetrasand; sys.path.insert(0, sys.argv[1]); import test_module as t; "
                "v, f = t.obj_arrays(t.CUBE); tetrasand.sdf((v, f[:-1]), resolution=16, backend='cpu')")
        run = subprocess.run([sys.executable, "-c", code, str(pathlib.Path(__file__).parent)],
                             capture_output=True, text=True, check=True)
        self.assertIn("<arrays>: the mesh is not closed", run.stderr)

    def test_saves_vdb_and_nvdb_and_refuses_other_suffixes(self):
        with tempfile.TemporaryDirectory() as out:
            for name in ("cube.vdb", "cube.nvdb"):
                self.field.save(os.path.join(out, name))
                self.assertGreater(os.path.getsize(os.path.join(out, name)), 1000)
            with self.assertRaisesRegex(tetrasand.InputError, r"cube\.png.*\.vdb"):
                self.field.save(os.path.join(out, "cube.png"))


class SceneTest(unittest.TestCase):
    def test_stepping_moves_the_grains_and_hands_out_arrays_of_the_right_shapes(self):
        scene = tetrasand.Scene(str(COLLISION), backend="cpu")
        self.assertEqual(scene.dt, 1e-6)
        before = scene.positions
        self.assertEqual(before.shape, (8, 3))               # two grains of four spheres
        self.assertEqual(scene.velocities.shape, (2, 3))
        self.assertEqual(scene.orientations.shape, (2, 4))
        report = scene.step(200)
        self.assertEqual(scene.steps, 200)
        self.assertAlmostEqual(scene.time, 200e-6, delta=1e-12)
        self.assertAlmostEqual(report["time"], scene.time)
        moved = np.linalg.norm(scene.positions - before, axis=1)
        np.testing.assert_allclose(moved, 0.5 * 200e-6, rtol=1e-6)  # 0.5 m/s, no contact yet, no gravity
        np.testing.assert_allclose(np.linalg.norm(scene.orientations, axis=1), 1.0, atol=1e-12)
        np.testing.assert_allclose(scene.velocities[:, 0], [0.5, -0.5], atol=1e-12)

    def test_the_gpu_pipeline_steps_as_the_cpu_reference_does(self):
        # On llvmpipe the GL kernels run on the CPU: the module finds them and the engines agree (the GPU
        # pipeline computes in float).
        gpu = tetrasand.Scene(str(COLLISION), backend="gpu")
        cpu = tetrasand.Scene(str(COLLISION), backend="cpu")
        gpu.step(300)
        cpu.step(300)
        self.assertEqual((gpu.engine, cpu.engine), ("gpu float", "cpu reference"))
        np.testing.assert_allclose(gpu.positions, cpu.positions, atol=1e-6)

    def test_run_scene_from_toml_text_writes_its_outputs(self):
        text = COLLISION.read_text()
        with tempfile.TemporaryDirectory() as out:
            times = []
            summary = tetrasand.run_scene(text, out, duration=2e-4, backend="cpu",
                                          progress=lambda t, step: times.append(t))
            self.assertEqual(summary["steps"], 200)
            self.assertEqual(summary["grains"], 2)
            self.assertTrue((pathlib.Path(out) / "metrics.csv").is_file())
        self.assertEqual(len(times), 5)  # step 0 and every 50 steps


    def test_a_pour_stepped_in_any_chunks_releases_its_grains_where_the_runner_does(self):
        # Outputs every 310 steps, not a multiple of the pour's check interval, and Python steps 137 at a
        # time: the emitters must still release at the runner's steps, or the two runs part.
        text = PILE.read_text().replace("duration = 3.0", "duration = 0.012").replace("every = 2000", "every = 310")
        with tempfile.TemporaryDirectory() as out:
            summary = tetrasand.run_scene(text, out, backend="cpu")
            with open(pathlib.Path(out) / "metrics.csv", newline="") as f:
                last = list(csv.DictReader(f))[-1]
        scene = tetrasand.Scene(text, backend="cpu")
        report = None
        while scene.steps < summary["steps"]:
            report = scene.step(min(137, summary["steps"] - scene.steps))
        self.assertGreater(summary["grains"], 10)
        self.assertEqual(int(last["step"]), scene.steps)
        for key in ("kinetic_translational_J", "potential_J"):  # metrics.csv keeps 9 digits
            self.assertAlmostEqual(float(last[key]), report[key], delta=2e-9 * abs(report[key]), msg=key)


class ErrorTest(unittest.TestCase):
    def test_a_missing_mesh_file_raises_input_error_naming_the_file(self):
        with self.assertRaises(tetrasand.InputError) as caught:
            tetrasand.sample("no/such/mesh.obj", count=10, backend="cpu")
        self.assertIn("no/such/mesh.obj", str(caught.exception))
        self.assertIsInstance(caught.exception, ValueError)

    def test_a_misspelt_scene_key_raises_input_error_naming_the_key(self):
        text = COLLISION.read_text().replace("duration = 0.01", "durashun = 0.01")
        with self.assertRaisesRegex(tetrasand.InputError, r"<string>:\d+: .*durashun"):
            tetrasand.Scene(text, backend="cpu")

    def test_a_size_the_mesh_cannot_take_names_the_mesh_and_what_fits(self):
        with self.assertRaisesRegex(tetrasand.InputError, r"cube\.obj: particle radius 10 m is too large.*below"):
            tetrasand.sample(str(CUBE), radius=10.0, backend="cpu", sdf_backend="cpu")
        with self.assertRaisesRegex(tetrasand.InputError, r"cube\.obj: a \d+ x .*smallest voxel size that fits"):
            tetrasand.sdf(str(CUBE), voxel=1e-7, backend="cpu")

    def test_an_open_mesh_is_refused_unless_winding_signs(self):
        vertices, faces = obj_arrays(CUBE)
        with self.assertRaisesRegex(tetrasand.InputError, r"<arrays>: is not a closed"):
            tetrasand.sample((vertices, faces[:-1]), count=50, backend="cpu", sdf_backend="cpu")

    def test_faces_naming_missing_vertices_are_refused(self):
        vertices, faces = obj_arrays(CUBE)
        faces[2, 1] = 99
        with self.assertRaisesRegex(tetrasand.InputError, r"row 2 names vertex 99; there are 8"):
            tetrasand.sdf((vertices, faces), backend="cpu")

    def test_bad_argument_values_raise_value_error(self):
        with self.assertRaisesRegex(ValueError, "backend='fast'"):
            tetrasand.sdf(str(CUBE), backend="fast")
        with self.assertRaisesRegex(ValueError, "count or radius, not both"):
            tetrasand.sample(str(CUBE), count=10, radius=0.01)


if __name__ == "__main__":
    unittest.main()
