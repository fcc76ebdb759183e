"""`import lightoctree`: bake, read/write round trips, inspect, convert, the
octree lookup and render, from Python (ctest python.module runs these)."""
import math
import os
import re

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


def test_write_refuses_a_name_that_is_not_a_vdb(grid, tmp_path):
    # A scene named as the output was replaced by a grid without a word.
    scene = tmp_path / "scene.gltf"
    scene.write_text("{}")
    with pytest.raises(lightoctree.InputError, match=r"^path: '.*scene.gltf' must end in .vdb"):
        lightoctree.write(str(scene), grid)
    assert scene.read_text() == "{}"


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
    # Behind: what the neighbours' surfaces reflect from below their planes
    # where their normals turn from the voxel's (edges and corners: the light
    # from below a voxel's surface, docs/render.md) and no more; 0.018 before
    # that light, 0.078 with it.
    assert back.mean() < 0.1 * front.mean()
    far = lightoctree.lookup(grid, np.full((2, 3), 1e6), np.tile([0.0, 1.0, 0.0], (2, 1)))
    np.testing.assert_array_equal(far, 0.0)
    with pytest.raises(ValueError):
        lightoctree.lookup(grid, np.zeros((3, 2)), np.zeros((3, 2)))


def test_a_grid_is_made_by_the_module_not_directly(grid):
    """Grid.__new__(Grid) gave an object allocated but never constructed,
    whose lookup crashed the interpreter: only the module makes grids."""
    for make in (lambda: lightoctree.Grid.__new__(lightoctree.Grid), lambda: lightoctree.Grid()):
        with pytest.raises(TypeError, match="made by read"):
            make()
    assert grid.size > 0  # the module's own grids are still made


@pytest.mark.parametrize("argument, bad", [
    ("points", [math.nan, 0.5, 0.5]), ("points", [0.5, math.inf, 0.5]),
    ("points", [0.5, 0.5, -math.inf]), ("points", [1e39, 0.5, 0.5]),  # inf as a float
    ("normals", [math.nan, 1.0, 0.0]), ("normals", [0.0, -math.inf, 0.0]),
    ("normals", [0.0, 0.0, 0.0])])
def test_lookup_refuses_points_and_normals_it_has_no_answer_for(grid, argument, bad):
    """A NaN or infinite point gave 0, dark light a caller cannot tell from
    a real answer: refused by the argument's name and the row, as the
    module's other arguments are, and no answer for any row."""
    points = np.tile(np.asarray(grid.positions)[0], (4, 1))
    normals = np.tile([0.0, 1.0, 0.0], (4, 1))
    assert np.all(np.isfinite(lightoctree.lookup(grid, points, normals)))
    (points if argument == "points" else normals)[2] = bad
    with pytest.raises(lightoctree.InputError, match=argument + r": row 2 is \("):
        lightoctree.lookup(grid, points, normals)


def test_lookup_refuses_points_that_are_not_real_numbers(grid):
    """Bool points were taken as 1 and 0, complex ones lost their imaginary
    part with only NumPy's warning (H11-1-28/29): refused by name."""
    normals = np.tile([0.0, 1.0, 0.0], (2, 1))
    for bad in (np.ones((2, 3), bool), np.ones((2, 3), complex), np.full((2, 3), "1")):
        with pytest.raises(lightoctree.InputError, match=r"points: must be an array of numbers of shape \(N, 3\)"):
            lightoctree.lookup(grid, bad, normals)
    with pytest.raises(lightoctree.InputError, match=r"normals: must be an array of numbers"):
        lightoctree.lookup(grid, np.ones((2, 3)), normals.astype(bool))
    # Objects that are text or bools are no numbers either (H12-1-34, -35).
    for bad in (np.array([["0", "0.27", "-0.28"]] * 2, object), np.ones((2, 3), bool).astype(object)):
        with pytest.raises(lightoctree.InputError, match=r"points: must be an array of numbers"):
            lightoctree.lookup(grid, bad, normals)


def test_three_numbers_are_three_real_numbers_and_text_has_no_nul(tmp_path):
    """sky=(True, True, True) lit as (1, 1, 1), and a complex array as its
    real part with only NumPy's warning (H12-1-35, -60); camera='a\\x00b' was
    named cut at the NUL (H12-1-66)."""
    for bad in ((True, True, True), np.ones(3, complex), (1, 2), "1,2"):
        with pytest.raises(lightoctree.InputError, match="sky: expected three numbers"):
            lightoctree.bake(SCENE, depth=3, photons=1000, sky=bad)
    with pytest.raises(lightoctree.InputError, match="camera: must be a string without NUL bytes"):
        lightoctree.reference(SCENE, width=4, height=3, spp=1, camera="a\x00b")
    # bytes are no triple (b'abc' was taken as 97, 98, 99), a lone surrogate
    # no text (pybind11's bare "Unable to cast", H13-1-5, -63).
    with pytest.raises(lightoctree.InputError, match="eye: expected three numbers"):
        lightoctree.reference(SCENE, width=4, height=3, spp=1, eye=b"abc", target=(0, 0.3, 0))
    with pytest.raises(lightoctree.InputError, match="camera: must be a string of text"):
        lightoctree.reference(SCENE, width=4, height=3, spp=1, camera="\udcff")


def test_settings_that_would_be_dropped_are_refused(grid_file, tmp_path):
    """An empty camera name drew from the first camera, and direction pages
    asked of a lightmap of the full light were left out, without a word
    (H17-4-1): both refused, nothing written."""
    with pytest.raises(lightoctree.InputError, match="camera: an empty name"):
        lightoctree.reference(SCENE, width=4, height=3, spp=1, camera="")
    out = tmp_path / "full.glb"
    with pytest.raises(lightoctree.InputError,
                       match="directions on: a lightmap of the full light writes no direction"):
        lightoctree.lightmap(SCENE, grid_file, str(out), content="full", directions="on")
    assert list(tmp_path.iterdir()) == []


def test_render_draws_the_scene_lit_by_the_grid(grid):
    image = lightoctree.render(SCENE, grid, width=64, height=48, mode="indirect")
    assert image.shape == (48, 64, 3) and image.dtype == np.float32
    assert np.all(np.isfinite(image)) and image.mean() > 0


def test_render_in_a_child_forked_after_a_render_fails_at_once(grid):
    """A render in an os.fork child after one in the parent waited forever
    (Mesa's threads stay in the parent). It now raises at once, naming the
    'spawn' start method; the child is killed after 60 s so that a hang
    fails the test instead of the suite."""
    import signal
    import time
    lightoctree.render(SCENE, grid, width=16, height=12)
    read_end, write_end = os.pipe()
    pid = os.fork()
    if pid == 0:
        os.close(read_end)
        outcome = b"returned"
        try:
            lightoctree.render(SCENE, grid, width=16, height=12)
        except RuntimeError as e:
            outcome = ("raised: " + str(e)).encode()
        except BaseException as e:  # noqa: B036 - anything else is a failure, reported
            outcome = ("raised another error: " + repr(e)).encode()
        os.write(write_end, outcome[:4000])
        os._exit(0)
    os.close(write_end)
    deadline = time.monotonic() + 60
    while True:
        done, status = os.waitpid(pid, os.WNOHANG)
        if done:
            break
        if time.monotonic() > deadline:
            os.kill(pid, signal.SIGKILL)
            os.waitpid(pid, 0)
            os.close(read_end)
            pytest.fail("the render in the forked child did not end within 60 s")
        time.sleep(0.05)
    with os.fdopen(read_end, "rb") as pipe:
        outcome = pipe.read().decode()
    assert os.waitstatus_to_exitcode(status) == 0, outcome
    assert outcome.startswith("raised: "), outcome
    assert "fork" in outcome and "spawn" in outcome, outcome
    # The parent still renders.
    assert lightoctree.render(SCENE, grid, width=16, height=12).mean() > 0


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


def test_bake_takes_the_sky_and_the_representation():
    """The sky keywords light the bake as the --sky flags do (the Cornell
    box's open front lets the sky in; none given is the file's own, black),
    representation picks the payload, and bad values are refused by name."""
    settings = dict(depth=4, photons=30000, knn=40)
    dark = lightoctree.bake(SCENE, **settings)
    unlit_sky = lightoctree.bake(SCENE, sky=(0, 0, 0), **settings)
    np.testing.assert_array_equal(unlit_sky.irradiance, dark.irradiance)
    lit = lightoctree.bake(SCENE, sky=(5, 5, 5), **settings)
    assert lit.irradiance.mean() > 2 * dark.irradiance.mean()
    assert dark.sh_terms == 0
    sh = lightoctree.bake(SCENE, representation="sh1", **settings)
    assert sh.sh_terms == 4 and not np.any(sh.vdl_count)
    with pytest.raises(lightoctree.InputError, match="representation: must be vdl, sh1 or sh2"):
        lightoctree.bake(SCENE, representation="vdls", **settings)
    with pytest.raises(lightoctree.InputError, match="^sky: "):
        lightoctree.bake(SCENE, sky=(-1, 0, 0), **settings)


def test_advice_that_names_a_command_names_the_program(tmp_path):
    """A photon map read as a grid is refused with the command that reads it,
    whose flag the module's convert does not take: named as the program's,
    not as a keyword ("`convert photon_map`", H17-1-2)."""
    cli = os.environ.get("LIGHTOCTREE_CLI")
    if not cli:
        pytest.skip("LIGHTOCTREE_CLI not set (ctest sets it)")
    import subprocess
    photons = str(tmp_path / "photons.vdb")
    subprocess.run([cli, "bake", SCENE, "-o", str(tmp_path / "grid.vdb"), "--depth", "3",
                    "--photons", "3000", "--knn", "20", "--photon-map", photons, "--quiet"],
                   check=True)
    with pytest.raises(lightoctree.InputError,
                       match="read only beside its grid, by `lightoctree convert --photon-map`"):
        lightoctree.read(photons)


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
    with pytest.raises(lightoctree.InputError,
                       match=r"depth: must be 0 \(the grid's own\) or a whole number from 1 to 12, got -1"):
        lightoctree.convert(grid, depth=-1)
    with pytest.raises(lightoctree.InputError, match="depth"):
        lightoctree.convert(grid, depth=13)
    assert lightoctree.convert(grid).depth == grid.depth  # 0: the grid's own


# Every argument is checked by the module and refused by its name, whatever
# its type: pybind11's own conversion answered a negative photons, a NaN
# supersample or a tolerance "0.1" with a TypeError naming no argument
# ("incompatible function arguments" and the whole signature), and took
# True for 1. The refusal comes before any work (the scene is missing).
@pytest.mark.parametrize("call, argument, value", [
    ("bake", "photons", -5), ("bake", "photons", 2.5), ("bake", "photons", "1000"),
    ("bake", "depth", True), ("bake", "depth", "4"), ("bake", "depth", 4.5),
    ("bake", "knn", math.nan), ("bake", "knn", None), ("bake", "seed", -1), ("bake", "seed", 1.0),
    ("bake", "seed", True), ("bake", "target_error", "0.1"), ("bake", "target_error", 1j),
    ("bake", "include_direct", 1), ("bake", "vdls", 9), ("bake", "vdls", True),
    ("bake", "target_light", 0), ("bake", "depth", 10 ** 400), ("bake", "scene", 3),
    ("render", "supersample", math.nan), ("render", "supersample", True),
    ("render", "tolerance", "0.1"), ("render", "tolerance", 1.5), ("render", "width", -1),
    ("render", "height", 2.5), ("render", "interpolation", 1), ("render", "emitter_lights", 17),
    ("render", "shadow_map_size", np.True_), ("render", "mode", None), ("render", "texels", 16),
    ("reference", "spp", 2.5), ("reference", "width", True), ("reference", "std_error", "yes"),
    ("reference", "seed", 2 ** 64), ("reference", "fov", "45"),
    ("compare", "bin", True), ("compare", "clip_percentile", "99"),
    ("compare", "ignore_background", 0),
    ("convert", "depth", False), ("convert", "depth", -1.0), ("convert", "vdls", 4.0),
    ("convert", "vdls", 9), ("convert", "vdls", "four"),
    ("lightmap", "atlas", True), ("lightmap", "texel_size", "0.1"), ("lightmap", "chart_image", 1),
    ("read", "path", 3), ("write", "path", None),
])
def test_every_argument_is_refused_by_its_name(grid, call, argument, value, tmp_path):
    missing = str(tmp_path / "missing.gltf")
    image = np.ones((4, 4, 3), dtype=np.float32)
    calls = {
        "bake": lambda **kw: lightoctree.bake(**dict(dict(scene=missing), **kw)),
        "render": lambda **kw: lightoctree.render(missing, grid, **kw),
        "reference": lambda **kw: lightoctree.reference(missing, **kw),
        "compare": lambda **kw: lightoctree.compare(image, image, **kw),
        "convert": lambda **kw: lightoctree.convert(grid, **kw),
        "lightmap": lambda **kw: lightoctree.lightmap(missing, missing, str(tmp_path / "lit.glb"), **kw),
        "read": lambda **kw: lightoctree.read(**kw),
        "write": lambda **kw: lightoctree.write(grid=grid, **kw),
    }
    with pytest.raises(lightoctree.InputError) as refusal:
        calls[call](**{argument: value})
    assert str(refusal.value).startswith(argument + ": must be "), str(refusal.value)
    assert len(str(refusal.value)) < 200, str(refusal.value)
    assert list(tmp_path.iterdir()) == []


def test_numbers_of_any_numeric_type_are_taken():
    """What the checks take: NumPy integers and whole floats where a whole
    number is expected (as the flags take "4.0"), a NumPy bool where a bool
    is, the number of VDLs as a number; the bake runs with them."""
    g = lightoctree.bake(SCENE, depth=np.int64(3), photons=2000.0, knn=np.int32(20), seed=np.uint64(3),
                         vdls=2, include_direct=np.False_, target_error=0)
    assert g.depth == 3 and g.max_vdls == 2 and g.stats["stored_photons"] == 2000
    assert lightoctree.convert(g, depth=np.int8(2)).depth == 2


def test_a_name_that_is_only_an_extension_is_named_so(grid, grid_file, tmp_path):
    """write('.vdb', g) said "'.vdb' must end in .vdb": to the system '.vdb' is a
    hidden name without an extension. The refusal says what is missing."""
    for name in (".vdb", ".VDB"):
        with pytest.raises(lightoctree.InputError, match=r"^path: '.*/" + re.escape(name) +
                           r"' has no name before \.vdb: name the file \(grid\.vdb\)$"):
            lightoctree.write(str(tmp_path / name), grid)
    with pytest.raises(lightoctree.InputError,
                       match=r"^output: '.*/\.glb' has no name before \.glb"):
        lightoctree.lightmap(SCENE, grid_file, str(tmp_path / ".glb"))
    assert list(tmp_path.iterdir()) == []


def test_file_names_that_are_not_utf8_are_taken_as_open_takes_them(grid, tmp_path):
    """A name that is not UTF-8 comes as bytes, as the str of os.fsdecode (its
    bytes as surrogate escapes) or as an os.PathLike of either: bytes were
    refused, the others raised UnicodeEncodeError, a warning naming one raised
    UnicodeDecodeError. Every function takes them as open() does, returns
    them as os.fsdecode does and names them with the bytes shown as \\xNN."""
    import pathlib
    import warnings

    folder = os.fsencode(tmp_path) + b"/odd-\xff\xfe"
    os.mkdir(folder)
    raw = folder + b"/grid.vdb"
    text = os.fsdecode(raw)

    class BytesPath:
        def __fspath__(self):
            return raw

    lightoctree.write(raw, grid)
    for path in (raw, text, pathlib.Path(text), BytesPath()):
        assert lightoctree.read(path).size == grid.size
        report = lightoctree.inspect(path)
        assert report["ok"] and report["path"] == text
    scene = folder + b"/scene.gltf"
    with open(SCENE, "rb") as source, open(scene, "wb") as copy:
        copy.write(source.read())
    baked = lightoctree.bake(scene, depth=3, photons=2000, knn=20)
    lightoctree.write(text, baked)
    with open(scene, "ab") as f:
        f.write(b" ")  # another scene: the warnings name its folder
    with pytest.warns(UserWarning, match=r"baked from .*/odd-\\xff\\xfe/scene\.gltf"):
        assert lightoctree.render(os.fsdecode(scene), baked, width=8, height=8).shape == (8, 8, 3)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        result = lightoctree.lightmap(scene, BytesPath(), folder + b"/lit.glb", directions="off")
    assert result["gltf"] == os.fsdecode(folder + b"/lit.glb") and os.path.exists(result["gltf"])
    assert all(os.path.exists(p) for p in result["page_files"])
    page = result["page_files"][0]
    assert lightoctree.compare(lightoctree.read_image(page), page)["reference"] == page
    with pytest.raises(lightoctree.InputError, match=r"/odd-\\xff\\xfe/missing\.vdb: "):
        lightoctree.read(folder + b"/missing.vdb")
    # A str no file system encoding holds (a surrogate that escapes no byte).
    with pytest.raises(lightoctree.InputError,
                       match=r"^path: '\\ud800\.vdb' is not a file name the system can take"):
        lightoctree.read("\ud800.vdb")


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


# reference, compare and lightmap: the commands from Python (issue 44, part 2),
# with the commands' settings and defaults, so each equals its command's output.

def _cli():
    cli = os.environ.get("LIGHTOCTREE_CLI")
    if not cli:
        pytest.skip("LIGHTOCTREE_CLI not set (ctest sets it)")
    return cli


def _run(*args):
    import subprocess
    return subprocess.run([_cli(), *map(str, args)], check=True, capture_output=True, text=True)


def test_reference_equals_the_command(tmp_path):
    """The same seed and settings give the command's floats, with the scene's
    camera and with --eye/--target/--fov; the standard error alike."""
    calls = []
    image, error = lightoctree.reference(SCENE, width=16, height=12, spp=4, std_error=True,
                                         progress=lambda *report: calls.append(report))
    assert image.shape == error.shape == (12, 16, 3) and image.dtype == np.float32
    assert image.mean() > 0 and error.mean() > 0
    assert calls and all(task == "Path tracing" and 0 <= done <= total for task, done, total in calls)
    _run("reference", SCENE, "-o", tmp_path / "ref.exr", "--std-error", tmp_path / "se.exr",
         "--width", 16, "--height", 12, "--spp", 4, "--quiet")
    assert np.array_equal(lightoctree.read_image(str(tmp_path / "ref.exr")), image)
    assert np.array_equal(lightoctree.read_image(str(tmp_path / "se.exr")), error)
    view = dict(eye=(0.1, 0.3, 1.2), target=(0.0, 0.25, 0.0), fov=50)
    moved = lightoctree.reference(SCENE, width=16, height=12, spp=4, part="indirect", seed=7,
                                  max_bounces=5, **view)
    _run("reference", SCENE, "-o", tmp_path / "moved.exr", "--width", 16, "--height", 12,
         "--spp", 4, "--part", "indirect", "--seed", 7, "--max-bounces", 5,
         "--eye", "0.1,0.3,1.2", "--target", "0,0.25,0", "--fov", 50, "--quiet")
    assert np.array_equal(lightoctree.read_image(str(tmp_path / "moved.exr")), moved)
    assert not np.array_equal(moved[..., :], image)


def test_reference_std_error_of_one_sample_is_refused_as_by_the_command():
    """One sample per pixel says nothing of its spread: the command refuses
    --std-error with --spp 1, and Python returned an all-zero standard error
    that compare(reference_error=) took for a noiseless reference."""
    with pytest.raises(ValueError, match=r"^std_error needs spp 2 or more"):
        lightoctree.reference(SCENE, width=8, height=6, spp=1, std_error=True)
    # A time budget that allowed one pass (256 x 256 paths take longer than 1 ms).
    with pytest.raises(ValueError, match="time_budget allowed one sample per pixel"):
        lightoctree.reference(SCENE, width=256, height=256, time_budget=1e-3, std_error=True)
    assert lightoctree.reference(SCENE, width=8, height=6, spp=1).shape == (6, 8, 3)


def test_reference_defaults_are_the_commands():
    text = lightoctree.reference.__doc__
    for default in ("width: int = 800", "height: int = 600", "spp: int = 64", "part: str = 'full'",
                    "seed: int = 1", "max_bounces: int = 256"):
        assert default in text, default


@pytest.mark.parametrize("argument, value, message", [
    ("spp", -1, "spp: must be a whole number from 1 to 1000000, got -1"),
    ("spp", 0, "spp: must be"),
    ("width", 0, "width: must be"),
    ("max_bounces", -1, "max_bounces: must be"),
    ("fov", math.nan, "fov: must be a finite number from 1 to 179, got nan"),
    ("fov", 180, "fov: must be"),
    ("time_budget", math.nan, "time_budget: must be"),
    ("time_budget", -1.0, "time_budget: must be"),
    ("part", "edges", "part: must be one of 'full', 'direct', 'indirect', 'irradiance', got 'edges'"),
    ("seed", -1, "seed: must be a whole number from 0"),
    ("eye", (1, 2), "eye: expected three numbers"),
    ("eye", (1, 2, math.nan), "eye: expected three numbers"),
    ("eye", (0, 1, 2), "eye and target must be given together"),
    ("camera", "nowhere", "camera: no camera named 'nowhere'"),
    ("sky", (1, -1, 1), "sky: .* is not a radiance"),
])
def test_reference_refuses_bad_arguments_by_name(argument, value, message):
    with pytest.raises(ValueError, match=message):
        settings = dict(width=8, height=8, spp=1)
        if argument == "eye" and "together" not in message:
            settings["target"] = (0, 0, 0)
        lightoctree.reference(SCENE, **dict(settings, **{argument: value}))


@pytest.mark.parametrize("argument, flag, value", [
    ("spp", "--spp", v) for v in (0, 1, 1000000, 1000001)
] + [
    ("max_bounces", "--max-bounces", v) for v in (-1, 0, 100000, 100001)
] + [
    ("width", "--width", v) for v in (0, 1, 16384, 16385)
] + [
    ("fov", "--fov", v) for v in (math.nan, math.inf, 0.5, 1.0, 179.0, 179.5)
] + [
    ("time_budget", "--time-budget", v) for v in (math.nan, 0.0, 1e-4, 1e-3, 1e7, 2e7)
])
def test_reference_takes_what_the_flags_take(argument, flag, value, tmp_path):
    """Each value goes to the module and to `lightoctree reference`: both
    refuse it or both take it (then both fail on the missing scene)."""
    import subprocess
    missing = str(tmp_path / "missing.gltf")
    with pytest.raises(ValueError) as refusal:
        lightoctree.reference(missing, **{argument: value})
    module_refused = str(refusal.value).startswith(argument + ": must be")
    run = subprocess.run([_cli(), "reference", SCENE, "-o", str(tmp_path / "no-folder" / "x.exr"),
                          flag, repr(value)], capture_output=True, text=True)
    assert run.returncode in (1, 2), run.stderr
    flag_refused = run.returncode == 2 and (flag + ": must be") in run.stderr
    assert module_refused == flag_refused, (str(refusal.value), run.stderr)


class Stop(Exception):
    pass


def test_a_progress_callback_that_raises_stops_the_work():
    calls = []

    def progress(task, done, total):
        calls.append((task, done, total))
        if done > 0:
            raise Stop("enough")

    import time
    start = time.monotonic()
    with pytest.raises(Stop, match="enough"):
        lightoctree.reference(SCENE, width=160, height=120, spp=4096, progress=progress)
    # 160 x 120 at 4096 spp takes minutes; stopped at the first report after
    # the start, with no report after the one that raised.
    assert time.monotonic() - start < 20
    assert calls[-1][1] > 0 and sum(1 for _, done, _ in calls if done > 0) == 1
    calls.clear()
    with pytest.raises(Stop):
        lightoctree.bake(SCENE, depth=4, photons=2000000, progress=progress)
    assert sum(1 for _, done, _ in calls if done > 0) == 1


def test_ctrl_c_stops_the_work():
    """SIGINT during the work: the next progress report on the main thread
    runs Python's handler (PyErr_CheckSignals) and the call raises
    KeyboardInterrupt, with or without a callback."""
    import signal
    import threading
    import time
    timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            lightoctree.reference(SCENE, width=160, height=120, spp=4096)
    finally:
        timer.cancel()
    assert time.monotonic() - start < 20
    # A few pixels of many samples: a percent of the work takes half a
    # minute, and reports come a quarter second apart as well (H10-1-118).
    reports = []
    timer = threading.Timer(0.5, os.kill, (os.getpid(), signal.SIGINT))
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            lightoctree.reference(SCENE, width=16, height=12, spp=1_000_000,
                                  progress=lambda task, done, total: reports.append((done, total)))
    finally:
        timer.cancel()
    done, total = reports[-1]
    assert 0 < done < total // 100, reports


def test_ctrl_c_stops_a_long_lookup_and_is_never_a_bad_argument(grid):
    """lookup of 4 M points heard Ctrl-C only when it ended (10^7 points:
    14 s, H14-1-2): its points go in chunks, Ctrl-C heard between them.
    And Ctrl-C while compare's arrays were converted was taken for a bad
    argument ("reference: must be ... got numpy.ndarray", H14-1-1)."""
    import signal
    import threading
    import time
    n = 4_000_000
    points = np.tile(np.array([[0.0, 0.27, -0.28]]), (n, 1))
    normals = np.tile(np.array([[0.0, 1.0, 0.0]]), (n, 1))
    start = time.monotonic()
    lightoctree.lookup(grid, points[:200_000], normals[:200_000])
    per_point = (time.monotonic() - start) / 200_000
    timer = threading.Timer(0.2, os.kill, (os.getpid(), signal.SIGINT))
    start = time.monotonic()
    timer.start()
    try:
        with pytest.raises(KeyboardInterrupt):
            lightoctree.lookup(grid, points, normals)
    finally:
        timer.cancel()
    took = time.monotonic() - start
    assert took < 0.2 + 0.25 * n * per_point, (took, n * per_point)
    # Ctrl-C (or a want of memory) while NumPy converts an argument.
    image = np.ones((64, 64, 3), np.float64)
    for raised in (KeyboardInterrupt, MemoryError):
        class Interrupted:
            def __array__(self, *args, **kwargs):
                raise raised()
        with pytest.raises(raised):
            lightoctree.compare(Interrupted(), image)
        with pytest.raises(raised):
            lightoctree.lookup(grid, Interrupted(), normals[:1])


def test_an_unknown_camera_names_the_first_ten_of_many(tmp_path):
    """An unknown camera listed every camera of the scene: 20,000 made one
    line of 249 KB (H14-5-2). The first ten, and how many more."""
    import json
    import shutil
    scene = json.load(open(SCENE))
    folder = os.path.dirname(SCENE)
    for buffer in scene.get("buffers", []):
        if "uri" in buffer and not buffer["uri"].startswith("data:"):
            shutil.copy(os.path.join(folder, buffer["uri"]), tmp_path)
    for i in range(30):
        scene.setdefault("cameras", []).append(
            {"name": f"cam{i}", "type": "perspective",
             "perspective": {"yfov": 0.7, "znear": 0.01, "aspectRatio": 1.0}})
        scene["nodes"].append({"camera": len(scene["cameras"]) - 1, "translation": [0, 0.3, 1]})
        scene["scenes"][0]["nodes"].append(len(scene["nodes"]) - 1)
    path = tmp_path / "cameras.gltf"
    path.write_text(json.dumps(scene))
    with pytest.raises(lightoctree.InputError) as refused:
        lightoctree.reference(str(path), width=8, height=8, spp=1, camera="nosuch")
    message = str(refused.value)
    assert re.search(r"no camera named 'nosuch' in .* \(it has '[^']*', .* and \d+ more\)$",
                     message), message
    assert len(message) < 600, message
    assert message.count("'cam") <= 10, message


def test_a_render_from_a_renders_own_callback_is_refused_by_name(grid):
    """A render called from the progress callback of a render on the same
    thread took its GL context: the outer render then failed naming a
    texture limit of 0 and advising a rebake (H14-1-3). Refused by name;
    from another thread, and after, a render works."""
    import threading
    inner = []

    def again(task, done, total):
        if not inner:
            inner.append(lightoctree.render(SCENE, grid, width=8, height=8))

    with pytest.raises(lightoctree.InputError, match=r"^render: called from the progress "
                       r"callback of a call that draws with OpenGL on this thread"):
        lightoctree.render(SCENE, grid, width=8, height=8, progress=again)
    assert not inner
    elsewhere = []

    def on_another_thread(task, done, total):
        if not elsewhere:
            worker = threading.Thread(target=lambda: elsewhere.append(
                lightoctree.render(SCENE, grid, width=8, height=8)))
            worker.start()
            worker.join()

    image = lightoctree.render(SCENE, grid, width=8, height=8, progress=on_another_thread)
    assert elsewhere and np.array_equal(elsewhere[0], image)
    assert np.array_equal(lightoctree.render(SCENE, grid, width=8, height=8), image)


def test_ctrl_c_stops_a_render_between_its_stages(grid):
    """A render told of its set-up's stages and frames: SIGINT during the
    set-up stops it at the next report, before any frame is drawn (a render
    heard Ctrl-C only once it returned, P26 of the seventh hostile list); an
    exception its callback raises stops it likewise."""
    import signal
    calls = []

    def interrupt(task, done, total):
        calls.append((task, done, total))
        if task == "render: set-up" and done == 1:
            os.kill(os.getpid(), signal.SIGINT)  # Python runs the handler at the next report

    with pytest.raises(KeyboardInterrupt):
        lightoctree.render(SCENE, grid, width=64, height=48, progress=interrupt)
    assert ("render: set-up", 1, 4) in calls
    assert not any(task == "render: frames" for task, _, _ in calls), calls
    # Uninterrupted, the same call reports the four stages and the four frames
    # of the rotated grid, and returns the picture.
    calls.clear()
    image = lightoctree.render(SCENE, grid, width=64, height=48,
                               progress=lambda *report: calls.append(report))
    assert image.shape == (48, 64, 3) and image.mean() > 0
    assert ("render: set-up", 4, 4) in calls and ("render: frames", 4, 4) in calls

    def stop(task, done, total):
        if task == "render: frames" and done == 1:
            raise Stop("after one frame")

    with pytest.raises(Stop, match="after one frame"):
        lightoctree.render(SCENE, grid, width=64, height=48, progress=stop)
    # Every call that takes a callback checks it first, by name (bake and
    # reference started their work and failed at the first report with a
    # bare "TypeError: 'int' object is not callable").
    with pytest.raises(lightoctree.InputError, match="progress: must be a callable"):
        lightoctree.render(SCENE, grid, width=64, height=48, progress=3)
    with pytest.raises(lightoctree.InputError, match="progress: must be a callable"):
        lightoctree.bake(SCENE, depth=4, photons=1000, progress=5)
    with pytest.raises(lightoctree.InputError, match="progress: must be a callable"):
        lightoctree.reference(SCENE, width=8, height=8, spp=1, progress=5)


def test_compare_measures_what_the_command_measures(tmp_path):
    image = lightoctree.reference(SCENE, width=16, height=12, spp=4)
    same = lightoctree.compare(image, image)
    assert same["compared_pixels"] == 16 * 12 and same["reference_noise"] is None
    for channel in ("R", "G", "B", "Y", "RGB"):
        assert same["channels"][channel] == {"rel_rmse": 0.0, "rel_mae": 0.0, "max_abs": 0.0}
    scaled = lightoctree.compare(image * 1.1, image)
    for channel in ("R", "G", "B", "Y", "RGB"):
        assert scaled["channels"][channel]["rel_rmse"] == pytest.approx(0.1, rel=1e-5)
        assert scaled["channels"][channel]["rel_mae"] == pytest.approx(0.1, rel=1e-5)
    assert scaled["mean_test_luminance"] == pytest.approx(1.1 * scaled["mean_reference_luminance"])

    # The command's --json on the same files: the same keys and values, with
    # every step (mask, black holes, clip, bin, the reference's noise).
    import json
    test, ref, se, mask = (str(tmp_path / name) for name in
                           ("test.exr", "ref.exr", "se.exr", "mask.png"))
    _run("reference", SCENE, "-o", test, "--width", 16, "--height", 12, "--spp", 2, "--seed", 2,
         "--quiet")
    _run("reference", SCENE, "-o", ref, "--std-error", se, "--geometry-mask", mask,
         "--width", 16, "--height", 12, "--spp", 4, "--quiet")
    for flags, settings in [
        ([], {}),
        (["--bin", "3", "--clip-percentile", "99", "--mask", mask, "--reference-error", se],
         dict(bin=3, clip_percentile=99, mask=mask, reference_error=se)),
        (["--ignore-background", "--bin", "2", "--clip-percentile", "90.5"],
         dict(ignore_background=True, bin=2, clip_percentile=90.5)),
    ]:
        report = str(tmp_path / "report.json")
        _run("compare", test, ref, "--json", report, "--quiet", *flags)
        with open(report) as f:
            expected = json.load(f)
        assert lightoctree.compare(test, ref, **settings) == expected, flags
        # Arrays give the same figures as the files they hold.
        arrays = {key: (lightoctree.read_image(value) if key == "reference_error" else value)
                  for key, value in settings.items()}
        from_arrays = lightoctree.compare(lightoctree.read_image(test), lightoctree.read_image(ref),
                                          **arrays)
        assert from_arrays == dict(expected, test=None, reference=None), flags


def _write_exr(path, image):
    """An uncompressed scanline EXR of 32-bit float B, G, R (the format's
    plainest form), so that a test can hand the command NaN pixels."""
    import struct
    height, width = image.shape[:2]

    def attribute(name, kind, value):
        return name.encode() + b"\0" + kind.encode() + b"\0" + struct.pack("<i", len(value)) + value

    channels = b"".join(c + b"\0" + struct.pack("<iB3xii", 2, 0, 1, 1) for c in (b"B", b"G", b"R"))
    window = struct.pack("<iiii", 0, 0, width - 1, height - 1)
    header = (b"\x76\x2f\x31\x01" + struct.pack("<i", 2) +
              attribute("channels", "chlist", channels + b"\0") +
              attribute("compression", "compression", b"\0") +
              attribute("dataWindow", "box2i", window) +
              attribute("displayWindow", "box2i", window) +
              attribute("lineOrder", "lineOrder", b"\0") +
              attribute("pixelAspectRatio", "float", struct.pack("<f", 1)) +
              attribute("screenWindowCenter", "v2f", struct.pack("<ff", 0, 0)) +
              attribute("screenWindowWidth", "float", struct.pack("<f", 1)) + b"\0")
    rows = []
    for y in range(height):
        data = b"".join(np.ascontiguousarray(image[y, :, c], dtype="<f4").tobytes() for c in (2, 1, 0))
        rows.append(struct.pack("<ii", y, len(data)) + data)
    offset = len(header) + 8 * height
    table = b""
    for row in rows:
        table += struct.pack("<Q", offset)
        offset += len(row)
    with open(path, "wb") as f:
        f.write(header + table + b"".join(rows))


def test_compare_warns_of_the_pixels_it_leaves_out(tmp_path):
    """A test image half NaN was scored over its other half without a word:
    the command warns on stderr and its --json counts them, the module warns
    through Python's warnings with the same sentence and the same figures."""
    import json
    import subprocess
    reference = lightoctree.reference(SCENE, width=16, height=12, spp=4)
    test = reference * 1.1
    test[:6] = np.nan  # the top half: 96 of 192 pixels
    test_file, reference_file = str(tmp_path / "half-nan.exr"), str(tmp_path / "reference.exr")
    _write_exr(test_file, test)
    _write_exr(reference_file, reference)
    assert np.array_equal(lightoctree.read_image(test_file), test, equal_nan=True)
    report = str(tmp_path / "report.json")
    run = subprocess.run([_cli(), "compare", test_file, reference_file, "--json", report, "--quiet"],
                         capture_output=True, text=True)
    assert run.returncode == 0, run.stderr
    sentence = ("96 pixels are not finite (NaN or infinite in the test image or the reference) "
                "and left out: the figures are of the 96 pixels compared")
    assert run.stderr == "warning: " + sentence + "\n"
    with open(report) as f:
        figures = json.load(f)
    assert figures["non_finite_image_pixels"] == 96 and figures["compared_pixels"] == 96
    assert figures["channels"]["Y"]["rel_rmse"] == pytest.approx(0.1, rel=1e-5)
    with pytest.warns(UserWarning) as caught:
        from_arrays = lightoctree.compare(test, reference)
    assert [str(w.message) for w in caught] == [sentence]
    assert from_arrays == dict(figures, test=None, reference=None)
    # Binned: the bins holding them are left out whole, and said so.
    with pytest.warns(UserWarning, match="96 pixels are not finite .*: the 8 bins of 4 x 4"):
        lightoctree.compare(test, reference, bin=4)
    # A finite image: no warning.
    import warnings
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert lightoctree.compare(reference, reference)["non_finite_image_pixels"] == 0


def test_compare_refuses_bad_arguments_by_name():
    image = np.ones((12, 16, 3), dtype=np.float32)
    with pytest.raises(ValueError, match="bin: must be a whole number from 1 to 1024, got 0"):
        lightoctree.compare(image, image, bin=0)
    with pytest.raises(ValueError, match="clip_percentile: must be .*got nan"):
        lightoctree.compare(image, image, clip_percentile=math.nan)
    with pytest.raises(ValueError, match="clip_percentile: must be"):
        lightoctree.compare(image, image, clip_percentile=0)
    with pytest.raises(ValueError, match="test is 16 x 8 but reference is 16 x 12"):
        lightoctree.compare(image[:8], image)
    with pytest.raises(ValueError, match=r"reference: must be a path or an array of numbers of shape \(height, width, 3\)"):
        lightoctree.compare(image, image[..., 0])
    with pytest.raises(ValueError, match="mask: the mask is 8 x 12, the images are 16 x 12"):
        lightoctree.compare(image, image, mask=image[:, :8])
    with pytest.raises(ValueError, match="reference_error: "):
        lightoctree.compare(image, image, reference_error=image[:4])
    # Text, bools and complex numbers are no image: refused by name, not
    # NumPy's bare "could not convert string to float" (H10-1-73).
    for bad in (np.full((12, 16, 3), "a", dtype=object), np.full((12, 16, 3), "a"),
                image.astype(bool), image.astype(complex)):
        with pytest.raises(lightoctree.InputError, match=r"test: must be a path or an array"):
            lightoctree.compare(bad, image)
    # An array of number objects is numbers; the refusal names the dtype
    # NumPy saw (it said "got shape (0,)", H12-1-52).
    assert lightoctree.compare(image.astype(object), image)["channels"]["RGB"]["rel_rmse"] == 0
    with pytest.raises(lightoctree.InputError, match="got an array of dtype complex128"):
        lightoctree.compare(image.astype(complex), image)
    # A mask may be bools, as it may be 0 and 1.
    half = np.zeros((12, 16), bool)
    half[:, :8] = True
    by_bools = lightoctree.compare(image, image * 1.1, mask=half)
    by_numbers = lightoctree.compare(image, image * 1.1, mask=half.astype(np.float32))
    assert by_bools["compared_pixels"] == by_numbers["compared_pixels"] == 12 * 8


@pytest.fixture(scope="module")
def grid_file(grid, tmp_path_factory):
    path = str(tmp_path_factory.mktemp("grid") / "grid.vdb")
    lightoctree.write(path, grid)
    return path


def test_lightmap_writes_what_the_command_writes(grid_file, tmp_path):
    """Defaults and a few settings: the same files, byte for byte (the atlas
    on the CPU is the same bytes on every run)."""
    for settings, flags in [({}, []),
                            (dict(atlas=256, image="png", directions="off", preview_unlit=True,
                                  texel_size=0.02, chart_image=True),
                             ["--atlas", "256", "--image", "png", "--directions", "off",
                              "--preview-unlit", "--texel-size", "0.02", "--chart-image"])]:
        module_dir, command_dir = tmp_path / "module", tmp_path / "command"
        for d in (module_dir, command_dir):
            d.mkdir(exist_ok=True)
            for f in d.iterdir():
                f.unlink()
        result = lightoctree.lightmap(SCENE, grid_file, str(module_dir / "lit.glb"), **settings)
        _run("lightmap", SCENE, grid_file, "-o", command_dir / "lit.glb", "--quiet", *flags)
        written = sorted(f.name for f in module_dir.iterdir())
        assert written == sorted(f.name for f in command_dir.iterdir()), settings
        for name in written:
            assert (module_dir / name).read_bytes() == (command_dir / name).read_bytes(), name
        assert result["gltf"] == str(module_dir / "lit.glb")
        assert result["pages"] == len(result["page_files"]) >= 1
        assert all(os.path.exists(p) for p in result["page_files"] + result["direction_files"])
        assert result["texel_size"] > 0 and result["output_bytes"] == os.path.getsize(result["gltf"])
        if settings:
            assert result["encoding"] == "rgbm-png" and result["direction_files"] == []
            assert result["preview"] == str(module_dir / "lit-preview.glb")
            assert result["texel_size"] == pytest.approx(0.02)
            assert len(result["chart_files"]) == result["pages"]
        else:
            assert result["encoding"] == "linear-exr" and result["preview"] is None
            assert len(result["direction_files"]) == result["pages"]


def test_lightmap_refuses_as_the_command_does(grid_file, tmp_path):
    import shutil
    scene = str(tmp_path / "scene.gltf")
    shutil.copy(SCENE, scene)
    before = open(scene, "rb").read()
    with pytest.raises(ValueError, match="output: .*scene.gltf' is the input scene"):
        lightoctree.lightmap(scene, grid_file, scene)
    copy = str(tmp_path / "lit-lightmap0.exr")  # an input named like a page of the output
    shutil.copy(grid_file, copy)
    with pytest.raises(ValueError, match="output: the lightmap pages of .* would replace the input lights"):
        lightoctree.lightmap(scene, copy, str(tmp_path / "lit.glb"))
    os.remove(copy)
    assert open(scene, "rb").read() == before
    with pytest.raises(ValueError, match="output: .*must end in"):
        lightoctree.lightmap(scene, grid_file, str(tmp_path / "lit.obj"))
    with pytest.raises(ValueError, match="lightmap: unknown setting 'atlas_size'"):
        lightoctree.lightmap(scene, grid_file, str(tmp_path / "lit.glb"), atlas_size=256)
    with pytest.raises(ValueError, match="atlas: must be a whole number from 8 to 16384, got 4"):
        lightoctree.lightmap(scene, grid_file, str(tmp_path / "lit.glb"), atlas=4)
    with pytest.raises(ValueError, match="texel_size: must be .*got nan"):
        lightoctree.lightmap(scene, grid_file, str(tmp_path / "lit.glb"), texel_size=math.nan)
    with pytest.raises(ValueError, match="content: must be one of 'indirect', 'full', got 'direct'"):
        lightoctree.lightmap(scene, grid_file, str(tmp_path / "lit.glb"), content="direct")
    assert sorted(os.listdir(tmp_path)) == ["scene.gltf"]


def test_render_and_lightmap_warn_of_a_grid_baked_from_another_scene(grid, grid_file, tmp_path):
    """The commands warn when the scene's content hash is not the one the
    grid records (tools/render_stages.h warnIfStale); the module's render and
    lightmap said nothing. Now the same sentence, through Python's warnings,
    and only then: a renamed copy of the same bytes is the same scene."""
    import shutil
    import warnings
    same, changed = str(tmp_path / "same.gltf"), str(tmp_path / "changed.gltf")
    shutil.copy(SCENE, same)
    shutil.copy(SCENE, changed)
    with open(changed, "a") as f:
        f.write(" ")  # one byte more: another scene as far as anyone can tell
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lightoctree.render(same, grid, width=16, height=12)
    stale = r": the light was baked from .*cornell-box.gltf \(fnv1a64:[0-9a-f]{16}\); '" + \
        re.escape(changed) + r"' and the files it reads differ \(fnv1a64:[0-9a-f]{16}\): " \
        r"bake again if the scene changed$"
    with pytest.warns(UserWarning, match="^grid" + stale):
        image = lightoctree.render(changed, grid, width=16, height=12)
    assert image.shape == (12, 16, 3)  # still drawn, as the command draws it
    out = tmp_path / "out"
    out.mkdir()
    with pytest.warns(UserWarning, match="^" + re.escape(grid_file) + stale):
        lightoctree.lightmap(changed, grid_file, str(out / "lit.glb"), directions="off")
    assert os.path.exists(out / "lit.glb")


def test_a_grid_with_the_direct_light_is_warned_before_the_work(tmp_path):
    """A grid baked with include_direct holds the direct light, which render's
    mode 'full' and lightmap's content 'full' add again: both warn, as the
    commands do (H16-7-1, H16-7-2), and lightmap before any file is written,
    so that warnings turned into errors stop it with nothing written
    (H16-1-3)."""
    import warnings
    path = str(tmp_path / "direct.vdb")
    lightoctree.write(path, lightoctree.bake(SCENE, depth=3, photons=3000, knn=20,
                                             include_direct=True))
    twice = "baked with include_direct: its VDLs hold the direct light, which "
    with pytest.warns(UserWarning, match="^grid: " + twice + "mode 'full' adds again"):
        lightoctree.render(SCENE, lightoctree.read(path), width=16, height=12)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        lightoctree.render(SCENE, lightoctree.read(path), width=16, height=12, mode="indirect")
    out = tmp_path / "out"
    out.mkdir()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(UserWarning, match=re.escape(path) + ": " + twice + ".*counted twice"):
            lightoctree.lightmap(SCENE, path, str(out / "lit.glb"), content="full",
                                 texel_size=0.05)
    assert os.listdir(out) == []


def test_the_scene_warnings_of_the_commands_are_python_warnings(grid, tmp_path):
    """What the loader warns of (an orthographic camera left out, a base
    colour above 1 clamped) the commands print as "warning: ..."; the
    module's calls said nothing. Each call that loads the scene warns."""
    import json
    with open(SCENE) as f:
        doc = json.load(f)
    doc["cameras"].append({"type": "orthographic",
                           "orthographic": {"xmag": 1, "ymag": 1, "znear": 0.1, "zfar": 10}})
    doc["nodes"].append({"name": "plan", "camera": len(doc["cameras"]) - 1})
    doc["scenes"][0]["nodes"].append(len(doc["nodes"]) - 1)
    path = str(tmp_path / "plan.gltf")
    with open(path, "w") as f:
        json.dump(doc, f)
    said = "camera 'plan' on node .* is orthographic, which lightoctree does not draw: left out"
    with pytest.warns(UserWarning, match=said):
        lightoctree.bake(path, depth=3, photons=2000, knn=20)
    with pytest.warns(UserWarning, match=said):
        lightoctree.reference(path, width=8, height=6, spp=1)
    with pytest.warns(UserWarning, match=said):
        lightoctree.render(path, grid, width=8, height=6)
    with pytest.warns(UserWarning, match=said):
        lightoctree.convert(grid, 3, scene=path)


def test_ctrl_c_during_lightmap_leaves_no_file_of_it(grid_file, tmp_path):
    """Ctrl-C during the export was raised only when it ended, its files
    written. Now each step reports (to `progress`, and to the interpreter's
    signal handlers), the last one after the last file and before the
    renames: a SIGINT there stops the export, its temporary files removed,
    and an earlier export's files stay as they were."""
    import signal
    out = tmp_path / "out"
    out.mkdir()
    output = str(out / "lit.glb")
    tasks = []

    def interrupt(task, done, total):
        tasks.append((task, done, total))
        if task == "lightmap: write" and done == total - 1:  # every file written, none renamed
            os.kill(os.getpid(), signal.SIGINT)

    with pytest.raises(KeyboardInterrupt):
        lightoctree.lightmap(SCENE, grid_file, output, progress=interrupt)
    assert [t for t, done, _ in tasks if done == 0] == ["lightmap: octree", "lightmap: UVs",
                                                  "lightmap: atlas", "lightmap: encode",
                                                  "lightmap: write"]
    # The atlas reports each row of texels: Ctrl-C within it is seen within a row.
    atlas = [(done, total) for t, done, total in tasks if t == "lightmap: atlas"]
    assert len(atlas) > 10 and atlas[-1][0] == atlas[-1][1] and atlas[-1][1] > 100
    assert os.listdir(out) == []  # not a file, not a temporary one
    # An earlier export (one page, no direction page) stays as it was, whole.
    lightoctree.lightmap(SCENE, grid_file, output, directions="off", image="png")
    before = {name: (out / name).read_bytes() for name in os.listdir(out)}
    assert sorted(before) == ["lit-lightmap0.png", "lit.glb"]
    with pytest.raises(KeyboardInterrupt):
        lightoctree.lightmap(SCENE, grid_file, output, progress=interrupt)
    assert {name: (out / name).read_bytes() for name in os.listdir(out)} == before

    # A callback that raises stops it at any step, the same way.
    for step in ("lightmap: octree", "lightmap: UVs", "lightmap: atlas", "lightmap: encode",
                 "lightmap: write"):
        def stop(task, done, total, step=step):
            if task == step and (step != "lightmap: atlas" or 0 < done < total // 2):
                raise Stop(step)  # the atlas in the middle of its rows
        with pytest.raises(Stop, match=step):
            lightoctree.lightmap(SCENE, grid_file, output, progress=stop)
        assert {name: (out / name).read_bytes() for name in os.listdir(out)} == before, step
    with pytest.raises(ValueError, match="progress: must be a callable"):
        lightoctree.lightmap(SCENE, grid_file, output, progress=3)


def test_render_checks_its_frame_against_the_memory_limit(grid, monkeypatch):
    """render ran 94 s to 3.5 GB under LIGHTOCTREE_MEMORY_LIMIT=200M (no
    watch stops it); its frame's memory is checked first, as the command's."""
    monkeypatch.setenv("LIGHTOCTREE_MEMORY_LIMIT", "50M")
    with pytest.raises(ValueError, match=r"^render: a frame of width 1000, height 1000, "
                       r"supersample 4 needs about [0-9.]+ MiB \(16,000,000 pixels drawn, 64 "
                       r"bytes each\), more than the 50.0 MiB of memory available"):
        lightoctree.render(SCENE, grid, width=1000, height=1000, supersample=4)


def test_the_memory_limit_stops_a_call_that_grows_past_it():
    """LIGHTOCTREE_MEMORY_LIMIT held in the module's estimates only, not
    while a call ran: a bake that grows past it now stops at its next
    progress report with MemoryError, as the command stops (which ends the
    process); the interpreter goes on. In a child, whose limit is its own
    resident memory after the import plus a little."""
    import subprocess
    import sys
    code = r"""
import os, sys, lightoctree
with open("/proc/self/statm") as f:
    rss = int(f.read().split()[1]) * os.sysconf("SC_PAGE_SIZE")
os.environ["LIGHTOCTREE_MEMORY_LIMIT"] = str(rss + (24 << 20))
try:
    lightoctree.bake(sys.argv[1], depth=5, photons=300000)
    print("not stopped")
except MemoryError as e:
    print("stopped:", e)
os.environ["LIGHTOCTREE_MEMORY_LIMIT"] = "8G"
print("after:", lightoctree.bake(sys.argv[1], depth=3, photons=5000).size > 0)
"""
    run = subprocess.run([sys.executable, "-c", code, SCENE], capture_output=True, text=True,
                         timeout=300)
    assert run.returncode == 0, run.stderr
    assert re.search(r"^stopped: bake: out of memory: the process grew to [0-9.]+ [KMG]iB, past "
                     r"LIGHTOCTREE_MEMORY_LIMIT=[0-9]+ \([0-9.]+ [KMG]iB\); stopped, nothing returned "
                     r"or written$", run.stdout, re.M), run.stdout
    assert "after: True" in run.stdout, run.stdout


def test_the_interpreter_ends_cleanly_with_daemon_threads_inside_calls():
    """Daemon threads inside long calls when the main thread ends: a thread
    that took the interpreter's lock during its shutdown was ended by a forced
    unwind, which the work's frames swallowed; the process aborted ("FATAL:
    exception not rethrown"), crashed or hung at exit in 6 of 8 runs
    (H12-1-71). The calls now stop and their threads wait for the end: every
    run exits 0, at once."""
    import subprocess
    import sys
    code = r"""
import sys, threading, time, lightoctree
def work(i):
    try:
        if i % 2:
            lightoctree.bake(sys.argv[1], depth=6, photons=2000000)
        else:
            lightoctree.reference(sys.argv[1], width=64, height=48, spp=100000)
    except BaseException:
        pass
threads = [threading.Thread(target=work, args=(i,), daemon=True) for i in range(3)]
for t in threads:
    t.start()
time.sleep(float(sys.argv[2]))
print("main ends")
"""
    for pause in ("0.05", "0.4", "1.0", "0.7"):
        run = subprocess.run([sys.executable, "-c", code, SCENE, pause], capture_output=True,
                             text=True, timeout=120)
        assert run.returncode == 0, (pause, run.returncode, run.stderr[-2000:])
        assert run.stdout == "main ends\n", run.stdout


def test_grids_and_arrays_of_another_type_are_refused_by_name(grid, tmp_path):
    """A grid argument that is not a Grid, or points that are not numbers, got
    pybind11's "incompatible function arguments ... Invoked with: None, ...",
    naming no argument (ninth hostile list H9-1-3)."""
    points, normals = np.zeros((1, 3)), np.array([[0, 1.0, 0]])
    for call, message in [
        (lambda: lightoctree.lookup(None, points, normals), "grid: must be a lightoctree.Grid"),
        (lambda: lightoctree.write(str(tmp_path / "x.vdb"), None), "grid: must be a lightoctree.Grid"),
        (lambda: lightoctree.convert(None, 3), "grid: must be a lightoctree.Grid"),
        (lambda: lightoctree.render(SCENE, "grid.vdb", width=8, height=8), "grid: must be a lightoctree.Grid"),
        (lambda: lightoctree.lookup(grid, np.array([[0, "a", 0]], dtype=object), normals),
         "points: must be an array of numbers of shape (N, 3)"),
        (lambda: lightoctree.lookup(grid, points, None), "normals: must be an array of numbers"),
        (lambda: lightoctree.lookup(grid, np.zeros((2, 2)), normals), "points: must be an array"),
        (lambda: lightoctree.lookup(grid, np.zeros((2, 3)), normals), "normals: 1 rows, where points has 2"),
    ]:
        with pytest.raises(lightoctree.InputError) as refusal:
            call()
        assert str(refusal.value).startswith(message), str(refusal.value)
    assert list(tmp_path.iterdir()) == []
    # Lists and integer arrays are numbers, as before.
    by_list = lightoctree.lookup(grid, [[0, 0.5, 0]], [[0, 1, 0]])
    assert by_list.shape == (1, 3)
    assert np.array_equal(by_list, lightoctree.lookup(grid, np.array([[0, 0.5, 0]]), np.array([[0, 1, 0]])))


def test_an_empty_path_is_named_as_empty():
    """read('') said "InputError: : file does not exist" (H9-1-4)."""
    for call, name in [(lightoctree.read, "path"), (lightoctree.inspect, "path"),
                       (lightoctree.read_image, "path"), (lightoctree.bake, "scene")]:
        with pytest.raises(lightoctree.InputError, match="^" + name + r": the path is empty: name a file$"):
            call("")


def test_reference_refuses_spp_with_a_time_budget_as_the_command_does():
    """spp=4 with time_budget=1.0 ran for the budget and ignored spp, where the
    command refuses "--spp excludes --time-budget" (H9-1-7)."""
    with pytest.raises(lightoctree.InputError, match="^spp and time_budget: give one of them"):
        lightoctree.reference(SCENE, width=8, height=8, spp=4, time_budget=1.0)
    assert lightoctree.reference(SCENE, width=8, height=8, spp=2).shape == (8, 8, 3)


def test_compare_refuses_a_negative_standard_error_and_warns_of_a_black_reference():
    """A negative reference_error was taken (reference_noise 0.909); against
    a black reference rel_rmse was inf without a word (H9-1-8)."""
    a = np.ones((8, 8, 3), np.float32)
    with pytest.raises(lightoctree.InputError,
                       match=r"^reference_error: pixel \(0, 0\) holds a standard error of -1 in channel R"):
        lightoctree.compare(a, a * 1.1, reference_error=-a)
    assert lightoctree.compare(a, a * 1.1, reference_error=0.01 * a)["reference_noise"] > 0
    with pytest.warns(UserWarning, match=r"the reference is black \(0\) in R, G, B, Y, RGB"):
        result = lightoctree.compare(a, np.zeros_like(a))
    assert math.isinf(result["channels"]["Y"]["rel_rmse"])
    assert result["channels"]["Y"]["max_abs"] > 0


def test_numbers_are_read_in_the_c_locale_whatever_the_program_set(tmp_path):
    """A program that sets a decimal-comma locale (Python's locale.setlocale,
    which sets the C library's) bakes with sky=(0.5, 0.5, 0.5) as the C locale
    does: the module's numbers are read and written in the C locale."""
    import shutil
    import subprocess
    import sys
    localedef = shutil.which("localedef")
    if localedef is None:
        pytest.skip("localedef (Debian's locales, which tools/setup.sh installs) is missing")
    subprocess.run([localedef, "-i", "de_DE", "-f", "UTF-8", str(tmp_path / "de_DE.UTF-8")],
                   check=True, capture_output=True)
    code = (
        "import locale, sys, numpy as np, lightoctree\n"
        "locale.setlocale(locale.LC_ALL, 'de_DE.UTF-8')\n"
        "assert locale.localeconv()['decimal_point'] == ','\n"
        "seen = set()\n"
        "report = lambda task, done, total: seen.add(locale.localeconv()['decimal_point'])\n"
        "g = lightoctree.bake(sys.argv[1], depth=3, photons=3000, knn=20, sky=(0.5, 0.5, 0.5),\n"
        "                     progress=report)\n"
        "print(repr(float(np.asarray(g.irradiance, dtype=np.float64).sum())))\n"
        "print(locale.localeconv()['decimal_point'])\n"
        "print(''.join(sorted(seen)))\n")
    env = dict(os.environ, LOCPATH=str(tmp_path))
    run = subprocess.run([sys.executable, "-c", code, SCENE], env=env, capture_output=True,
                         text=True, timeout=120)
    assert run.returncode == 0, run.stderr
    lit, point, in_callback = run.stdout.split()
    assert point == ",", "the program's own locale is given back after each call"
    # A progress callback runs in the program's locale, on every thread (H11-1-4).
    assert in_callback == ",", in_callback
    g = lightoctree.bake(SCENE, depth=3, photons=3000, knn=20, sky=(0.5, 0.5, 0.5))
    assert float(lit) == float(np.asarray(g.irradiance, dtype=np.float64).sum())


def _png_gray_to_rgb(path, values):
    """A one-row 8-bit RGB PNG whose pixels are the grey levels `values`."""
    import struct
    import zlib
    row = b"\0" + bytes(v for v in values for _ in range(3))

    def chunk(kind, data):
        return (struct.pack(">I", len(data)) + kind + data +
                struct.pack(">I", zlib.crc32(kind + data) & 0xffffffff))
    header = struct.pack(">IIBBBBB", len(values), 1, 8, 2, 0, 0, 0)
    with open(path, "wb") as f:
        f.write(b"\x89PNG\r\n\x1a\n" + chunk(b"IHDR", header) +
                chunk(b"IDAT", zlib.compress(row)) + chunk(b"IEND", b""))


def test_read_image_decodes_every_8_bit_value_by_the_srgb_curve(tmp_path):
    # The decode's table (one sRGB-to-linear value per 8-bit level) against
    # IEC 61966-2-1 in double precision; the array owns its floats and stays
    # valid after the call.
    path = str(tmp_path / "levels.png")
    _png_gray_to_rgb(path, range(256))
    image = lightoctree.read_image(path)
    assert image.shape == (1, 256, 3) and image.dtype == np.float32
    s = np.arange(256) / 255.0
    expected = np.where(s <= 0.04045, s / 12.92, ((s + 0.055) / 1.055) ** 2.4)
    for channel in range(3):
        assert np.allclose(image[0, :, channel], expected, rtol=1e-6, atol=1e-7)
    image[0, 0, 0] = 7.0  # writable, its own memory
    assert lightoctree.read_image(path)[0, 0, 0] == 0.0


def test_a_child_forked_after_the_import_ends_with_its_exit_status():
    """A child forked from a process that had imported the module hung at its
    exit, in OpenVDB's logger, whose threads the fork did not copy (H16-1-2).
    It ends, with its own status and its output flushed, whether it calls
    sys.exit or runs off the end of the script."""
    import subprocess
    import sys
    script = (
        "import os, sys, time\n"
        "import lightoctree\n"
        "pid = os.fork()\n"
        "if pid == 0:\n"
        "    print('child', flush=False)\n"
        "    sys.exit(int(sys.argv[1]))\n"
        "deadline = time.monotonic() + 30\n"
        "while time.monotonic() < deadline:\n"
        "    done, status = os.waitpid(pid, os.WNOHANG)\n"
        "    if done:\n"
        "        print('exit', os.waitstatus_to_exitcode(status))\n"
        "        sys.exit(0)\n"
        "    time.sleep(0.05)\n"
        "os.kill(pid, 9)\n"
        "print('hung')\n")
    for code in (0, 3):
        run = subprocess.run([sys.executable, "-c", script, str(code)], capture_output=True,
                             text=True, timeout=120)
        assert run.returncode == 0, run.stderr
        assert run.stdout.split() == ["child", "exit", str(code)], run.stdout


def test_out_of_memory_is_a_memory_error_naming_the_call():
    """Under an address-space limit, compare's allocation failure was a bare
    MemoryError('std::bad_alloc') (H16-1-5): it names the call and the
    limits, as the command does. In a fresh interpreter, whose limit this
    test's process does not share."""
    import subprocess
    import sys
    script = (
        "import resource, numpy as np, lightoctree\n"
        "a = np.random.default_rng(1).random((3000, 3000, 3), dtype=np.float32)\n"
        "soft, hard = resource.getrlimit(resource.RLIMIT_AS)\n"
        "resource.setrlimit(resource.RLIMIT_AS, (800 << 20, hard))\n"
        "try:\n"
        "    lightoctree.compare(a, a * 1.1)\n"
        "    print('returned')\n"
        "except MemoryError as e:\n"
        "    print('MemoryError:', e)\n")
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                         timeout=300)
    said = run.stdout.strip()
    if said == "returned":
        pytest.skip("compare fitted in 800 MiB of address space here")
    assert said.startswith("MemoryError: compare: out of memory (an allocation failed)"), \
        said + run.stderr
    assert "ulimit -v" in said and "LIGHTOCTREE_MEMORY_LIMIT" in said, said


def test_a_black_reference_is_warned():
    """A scene without light drew black with no word (H16-4-2)."""
    scene = os.path.join(os.path.dirname(__file__), "..", "..", "tests", "fuzz", "seeds", "gltf",
                         "no-light.gltf")
    with pytest.warns(UserWarning, match="every pixel is black: no light reaches"):
        image = lightoctree.reference(scene, width=8, height=8, spp=1)
    assert image.max() == 0


def test_an_error_raised_while_a_number_is_read_goes_on_as_itself(grid):
    """A real number whose __float__ raises KeyboardInterrupt, MemoryError or
    another error: the error went, and the argument was refused as not a
    number (H16-1-1). A TypeError or ValueError still means 'not a number'."""
    import numbers

    class Raising:
        def __init__(self, error):
            self.error = error

        def __float__(self):
            raise self.error("from __float__")
    numbers.Real.register(Raising)
    for error in (KeyboardInterrupt, MemoryError, RuntimeError):
        with pytest.raises(error, match="from __float__"):
            lightoctree.render(SCENE, grid, width=8, height=8, tolerance=Raising(error))
    with pytest.raises(lightoctree.InputError, match="tolerance: must be"):
        lightoctree.render(SCENE, grid, width=8, height=8, tolerance=Raising(ValueError))
