"""`import lightoctree`: bake, read/write round trips, inspect, convert, the
octree lookup and render, from Python (ctest python.module runs these)."""
import math
import os

import numpy as np
import pytest

import lightoctree

SCENE = os.path.join(os.path.dirname(__file__), "..", "..", "data", "cornell-box.gltf")


@pytest.fixture(scope="module")
def grid():
    tasks = []
    g = lightoctree.bake(SCENE, depth=4, photons=30000, knn=40,
                         progress=lambda task, done, total: tasks.append((task, done, total)))
    assert tasks, "the progress callback was never called"
    assert all(0 <= done <= total for _, done, total in tasks)
    return g


def test_bake_gives_arrays_that_keep_the_contract(grid):
    n, k = grid.size, grid.max_vdls
    assert n > 500 and grid.depth == 4 and k == 4
    assert grid.coords.shape == (n, 3) and grid.coords.dtype == np.int32
    assert grid.irradiance.shape == (n, 3) and grid.normals.shape == (n, 3)
    assert grid.vdl_irradiance.shape == (n, k, 3) and grid.vdl_direction.shape == (n, k, 3)
    assert np.all(grid.irradiance >= 0)
    # The contract: a voxel's irradiance is the sum of its VDLs'.
    np.testing.assert_allclose(grid.vdl_irradiance.sum(axis=1), grid.irradiance,
                               rtol=1e-4, atol=1e-4 * grid.irradiance.max())
    used = np.arange(k)[None, :] < grid.vdl_count[:, None]
    lengths = np.linalg.norm(grid.vdl_direction, axis=2)[used]
    np.testing.assert_allclose(lengths, 1.0, atol=1e-3)
    # Voxel centres lie inside the voxels their coordinates name.
    corner = np.array(grid.origin)
    np.testing.assert_allclose((grid.positions - corner) / grid.voxel_size - 0.5, grid.coords, atol=1e-3)
    assert grid.stats["stored_photons"] > 0


def test_arrays_are_read_only_views_that_keep_the_grid_alive():
    g = lightoctree.bake(SCENE, depth=3, photons=5000, knn=20)
    e = g.irradiance
    expected = e.copy()
    assert not e.flags.writeable
    with pytest.raises(ValueError):
        e[0, 0] = 1.0
    del g
    np.testing.assert_array_equal(e, expected)


def test_write_read_and_inspect_round_trip(grid, tmp_path):
    path = str(tmp_path / "grid.vdb")
    lightoctree.write(path, grid)
    back = lightoctree.read(path)
    assert back.size == grid.size and back.depth == grid.depth
    np.testing.assert_array_equal(back.coords, grid.coords)
    np.testing.assert_array_equal(back.irradiance, grid.irradiance)
    np.testing.assert_array_equal(back.vdl_direction, grid.vdl_direction)
    report = lightoctree.inspect(path)
    assert report["ok"], [c for c in report["checks"] if not c["passed"]]
    assert {"vdl_sum", "unit_directions", "readable"} <= {c["name"] for c in report["checks"]}


def test_convert_to_a_coarser_depth_keeps_the_light(grid):
    coarse = lightoctree.convert(grid, depth=3)
    assert coarse.depth == 3 and 0 < coarse.size < grid.size
    # The area-weighted merge keeps the light: the mean irradiance over the
    # voxels stays (1.005 measured).
    assert 0.9 < coarse.irradiance.mean() / grid.irradiance.mean() < 1.1


def test_lookup_sees_the_light_from_the_front_and_none_from_behind(grid):
    points, normals = grid.positions, np.asarray(grid.normals, dtype=np.float64)
    lit = np.linalg.norm(normals, axis=1) > 0.5
    front = lightoctree.lookup(grid, points[lit], normals[lit])
    back = lightoctree.lookup(grid, points[lit], -normals[lit])
    assert front.shape == (int(lit.sum()), 3)
    # At the voxels' own centres and normals the lookup gives about their
    # irradiance (interpolation mixes in the neighbours): brute-force mean.
    ratio = front.mean() / np.asarray(grid.irradiance)[lit].mean()
    assert 0.95 < ratio < 1.05, ratio  # 1.002 measured
    assert back.mean() < 0.05 * front.mean()  # 0.018 measured
    far = lightoctree.lookup(grid, np.full((2, 3), 1e6), np.tile([0.0, 1.0, 0.0], (2, 1)))
    np.testing.assert_array_equal(far, 0.0)
    with pytest.raises(ValueError):
        lightoctree.lookup(grid, np.zeros((3, 2)), np.zeros((3, 2)))


def test_render_draws_the_scene_lit_by_the_grid(grid):
    image = lightoctree.render(SCENE, grid, width=64, height=48, mode="indirect")
    assert image.shape == (48, 64, 3) and image.dtype == np.float32
    assert np.all(np.isfinite(image)) and image.mean() > 0


def test_errors_are_python_exceptions(tmp_path):
    with pytest.raises(lightoctree.InputError):
        lightoctree.read(str(tmp_path / "missing.vdb"))
    assert issubclass(lightoctree.InputError, ValueError)
    with pytest.raises(ValueError):
        lightoctree.bake(SCENE, photons=1000, target_error=0.1)
    with pytest.raises(lightoctree.InputError, match="target_light"):
        lightoctree.bake(SCENE, target_error=0.1, target_light="direct")


def test_target_light_chooses_the_noise_figure():
    """The default target weighs the indirect noise against the light seen
    (direct plus indirect): in the Cornell box it stops with fewer photons."""
    seen = lightoctree.bake(SCENE, depth=4, target_error=0.1)
    indirect = lightoctree.bake(SCENE, depth=4, target_error=0.1, target_light="indirect")
    assert "of the light seen" in seen.stats["noise"]
    assert "of the light seen" not in indirect.stats["noise"]
    assert seen.stats["stored_photons"] < indirect.stats["stored_photons"]


def test_render_equals_the_command(grid, tmp_path):
    """lightoctree.render and `lightoctree render` go through one render
    session: the same grid file at the same size gives the same floats."""
    cli = os.environ.get("LIGHTOCTREE_CLI")
    if not cli:
        pytest.skip("LIGHTOCTREE_CLI not set (ctest sets it)")
    import subprocess
    vdb = str(tmp_path / "grid.vdb")
    exr = str(tmp_path / "frame.exr")
    lightoctree.write(vdb, grid)
    subprocess.run([cli, "render", SCENE, vdb, "-o", exr, "--width", "64", "--height", "48",
                    "--quiet"], check=True)
    command = lightoctree.read_image(exr)
    module = lightoctree.render(SCENE, lightoctree.read(vdb), width=64, height=48)
    assert command.shape == module.shape == (48, 64, 3)
    assert module.mean() > 0
    assert np.array_equal(command, module), \
        f"mean absolute difference {np.abs(command - module).mean()}"
    # A setting reaches the picture: diffuse only differs from the default.
    diffuse = lightoctree.render(SCENE, lightoctree.read(vdb), width=64, height=48, specular=False)
    assert not np.array_equal(diffuse, module)
    with pytest.raises(lightoctree.InputError):
        lightoctree.render(SCENE, grid, width=8, height=8, no_such_setting=1)
    with pytest.raises(lightoctree.InputError):
        lightoctree.render(SCENE, grid, width=8, height=8, texels="double")


# The arguments are checked as the command's flags are: the same ranges, NaN
# and the infinities refused, 0 "not given" where it is the default (NaN and
# -1 used to become target_error's default without a word, and 1e-9 ran for
# a minute). Each value goes to the module and to `lightoctree bake`: both
# refuse it or both take it (the module then fails on the missing scene,
# the command on the missing output folder: no bake runs).
@pytest.mark.parametrize("argument, flag, value", [
    ("target_error", "--target-error", v) for v in
    (math.nan, math.inf, -math.inf, -1.0, 1e-9, 1e-4, 1.5, 1e-3, 0.07, 1.0)
] + [
    ("depth", "--depth", v) for v in (-1, 0, 13, 1, 12)
] + [
    ("knn", "--knn", v) for v in (0, 100001, 1, 100000)
] + [
    ("photons", "--photons", v) for v in (200000001, 1, 200000000)
])
def test_numeric_arguments_take_what_the_flags_take(argument, flag, value, tmp_path):
    missing = str(tmp_path / "missing.gltf")
    with pytest.raises(lightoctree.InputError) as refusal:
        lightoctree.bake(missing, **{argument: value})
    module_refused = str(refusal.value).startswith(argument + ": must be")
    low, high = {"target_error": (1e-3, 1), "depth": (1, 12), "knn": (1, 100000),
                 "photons": (1, 200000000)}[argument]
    assert module_refused == (not low <= value <= high), str(refusal.value)
    cli = os.environ.get("LIGHTOCTREE_CLI")
    if not cli:
        pytest.skip("LIGHTOCTREE_CLI not set (ctest sets it)")
    import subprocess
    run = subprocess.run([cli, "bake", SCENE, "-o", str(tmp_path / "no-folder" / "x.vdb"),
                          flag, repr(value)], capture_output=True, text=True)
    assert run.returncode in (1, 2), run.stderr
    flag_refused = run.returncode == 2 and (flag + ": must be") in run.stderr
    assert module_refused == flag_refused, (str(refusal.value), run.stderr)
    assert not (tmp_path / "no-folder").exists()


def test_convert_refuses_a_depth_it_would_have_ignored(grid):
    with pytest.raises(lightoctree.InputError, match="depth: must be a whole number from 1 to 12, got -1"):
        lightoctree.convert(grid, depth=-1)
    with pytest.raises(lightoctree.InputError, match="depth"):
        lightoctree.convert(grid, depth=13)
    assert lightoctree.convert(grid).depth == grid.depth  # 0: the grid's own


def test_a_path_with_a_nul_byte_names_no_file(grid, tmp_path):
    """Python's open() refuses "\\0" in a path; the module did not, and the
    system cut the path at it: write("a.vdb\\0.png") wrote a.vdb."""
    target = tmp_path / "grid.vdb"
    with pytest.raises(lightoctree.InputError, match=r"path: the path .*grid\.vdb\\0\.png' holds a NUL byte"):
        lightoctree.write(str(target) + "\0.png", grid)
    assert list(tmp_path.iterdir()) == []
    lightoctree.write(str(target), grid)
    for read in (lightoctree.read, lightoctree.inspect, lightoctree.read_image):
        with pytest.raises(lightoctree.InputError, match="path: .*NUL byte"):
            read(str(target) + "\0.exr")
    with pytest.raises(lightoctree.InputError, match="scene: .*NUL byte"):
        lightoctree.bake(SCENE + "\0.obj", depth=3, photons=1000)
    with pytest.raises(lightoctree.InputError, match="scene: .*NUL byte"):
        lightoctree.render(SCENE + "\0", grid, width=8, height=8)
    with pytest.raises(lightoctree.InputError, match="scene: .*NUL byte"):
        lightoctree.convert(grid, depth=5, scene=SCENE + "\0")
