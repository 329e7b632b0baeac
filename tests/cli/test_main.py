"""`python -m rtpy`: rendering, overrides, listing, exit codes, Ctrl-C."""

from __future__ import annotations

import errno
import os
import re
import select
import signal
import subprocess
import sys
import tempfile
import tomllib
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from PIL import Image

import rtpy
from rtpy.cli.main import build_parser, main, prepare
from rtpy.cli.options import MAX_WORKERS, UsageError, given_settings, parse_set
from rtpy.engine.renderer import Renderer
from rtpy.io.bundled import bundled_dir, bundled_scenes
from rtpy.io.image import read_pfm
from rtpy.materials import MATERIALS
from rtpy.render_settings import SETTINGS

from ..commands import modules_imported_by, read_until, rtpy_command, run_cli
from ..cores import module_outcomes, outcome
from ..tiers import slow_except

SMALL = ["--width", "16", "--spp", "1", "--quiet"]


def checked_by_the_command_line(*options: str) -> dict:
    """What the render gets from the command line's options, once rtpy.render's
    boundary has checked them: key -> its value as rtpy uses it."""
    args = build_parser(every_command=False).parse_args(["render", "scene.toml", *options])
    scene = rtpy.Scene([], camera=rtpy.Camera(width=4))
    given = given_settings(args)
    renderer = prepare(args, scene, Path("scene.toml"), given, None, None)
    where = {"width": renderer.camera, "background": renderer.scene, "sky": renderer.scene}
    return {key: getattr(where.get(key, renderer.settings), key) for key in given}


# --- the commands that need no files of the test's, run at once on every core ------------


def cli_scenes() -> subprocess.CompletedProcess:
    return run_cli("scenes")


def cli_render_small_in_an_empty_directory(extra, message) -> tuple:
    """(the finished command, the names of the files in the directory it ran in)."""
    with tempfile.TemporaryDirectory() as directory:
        result = run_cli("render", "week08_three_balls", *SMALL, *extra, cwd=directory)
        return result, os.listdir(directory)


def cli_render_three_balls(extra) -> subprocess.CompletedProcess:
    return run_cli("render", "week08_three_balls", *extra)


def cli_render_cornel() -> subprocess.CompletedProcess:
    return run_cli("render", "cornel")


def cli_without_a_command() -> subprocess.CompletedProcess:
    return run_cli()


def cli_render_without_a_scene() -> subprocess.CompletedProcess:
    return run_cli("render")


def cli_version() -> subprocess.CompletedProcess:
    return run_cli("--version")


# node id -> what the command of each selected test gave, all of them run at once (each
# child process starts Python and imports rtpy: most of their time).
commands = module_outcomes(
    {
        "test_scenes_lists_every_bundled_scene_with_its_description": cli_scenes,
        "test_bad_options_exit_2_and_write_nothing": cli_render_small_in_an_empty_directory,
        "test_argparse_errors_exit_2": cli_render_three_balls,
        "test_unknown_scene_name_exits_2": cli_render_cornel,
        "test_no_command_prints_the_full_help_naming_the_program_as_run": (cli_without_a_command),
        "test_errors_name_the_program_as_run": cli_render_without_a_scene,
        "test_version_is_the_installed_package_version": cli_version,
    }
)


def test_scenes_lists_every_bundled_scene_with_its_description(commands, request):
    result = outcome(commands, request)
    assert result.returncode == 0
    lines = result.stdout.strip().splitlines()
    names = [name for name, _ in bundled_scenes()]
    assert {"cornell", "week08_three_balls", "rtiow_cover"} <= set(names)
    assert len(lines) == len(names)
    for line, (name, description) in zip(lines, bundled_scenes(), strict=True):
        assert line.startswith(name) and line.endswith(description) and description


def test_render_writes_png_and_linear_matching_the_python_api(tmp_path):
    png, pfm, npy = tmp_path / "out.png", tmp_path / "out.pfm", tmp_path / "out.npy"
    assert main(["render", "week08_three_balls", *SMALL, "-o", str(png), "--linear", str(pfm)]) == 0
    assert main(["render", "week08_three_balls", *SMALL, "-o", str(png), "--linear", str(npy)]) == 0
    expected = rtpy.render(rtpy.load_scene("week08_three_balls"), width=16, spp=1).linear
    with Image.open(png) as im:
        assert im.size == (16, 9)
    np.testing.assert_array_equal(np.load(npy), expected)
    np.testing.assert_array_equal(read_pfm(pfm), expected.astype(np.float32))


def test_default_output_is_named_after_the_scene(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    assert main(["render", "week05_point_light", *SMALL]) == 0
    assert (tmp_path / "week05_point_light.png").is_file()


def test_overrides_reach_the_renderer(tmp_path):
    out = tmp_path / "o.npy"
    args = [
        "render",
        "week08_three_balls",
        "--width",
        "12",
        "--quiet",
        "-o",
        str(tmp_path / "o.png"),
    ]
    assert (
        main(
            [
                *args,
                "--integrator",
                "center",
                "--set",
                "sky=false",
                "--set",
                "background=[0.25, 0.5, 1]",
                "--linear",
                str(out),
            ]
        )
        == 0
    )
    image = np.load(out)
    # The top-left corner sees the sky direction; with sky off it is the background.
    np.testing.assert_array_equal(image[0, 0], [0.25, 0.5, 1.0])
    assert (
        main(
            [
                *args,
                "--spp",
                "2",
                "--max-depth",
                "2",
                "--seed",
                "4",
                "--set",
                "nee=false",
                "--linear",
                str(out),
            ]
        )
        == 0
    )
    scene = rtpy.load_scene("week08_three_balls")
    expected = rtpy.render(scene, width=12, spp=2, max_depth=2, seed=4, nee=False).linear
    np.testing.assert_array_equal(np.load(out), expected)


def test_set_mis_reaches_the_renderer_and_is_checked(tmp_path):
    out = tmp_path / "o.npy"
    args = ["render", "cornell", "--width", "12", "--spp", "2", "--seed", "3", "--quiet"]
    assert (
        main([*args, "-o", str(tmp_path / "o.png"), "--set", "mis=false", "--linear", str(out)])
        == 0
    )
    scene = rtpy.load_scene("cornell")
    expected = rtpy.render(scene, width=12, spp=2, seed=3, mis=False).linear
    np.testing.assert_array_equal(np.load(out), expected)
    assert not np.array_equal(expected, rtpy.render(scene, width=12, spp=2, seed=3).linear)
    assert main([*args, "-o", str(tmp_path / "p.png"), "--set", "mis=2"]) == 2
    assert not (tmp_path / "p.png").exists()


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "bad.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    "extra,message",
    slow_except(
        [
            (["--set", "bogus=1"], "bogus"),
            (["--set", "max_depth=0"], "--set max_depth: expected"),
            (["--set", "spp=2"], "--spp and --set spp set one value"),
            (["--set", "background=[1, 2]"], "background"),
            (["--set", "nee"], "KEY=VALUE"),
            (["-o", "no/such/dir/x.png"], "does not exist"),
            (["-o", "x.gif"], ".gif"),
            (["--linear", "x.png"], "x.png"),
        ],
        (["--set", "bogus=1"], "bogus"),
        (["-o", "no/such/dir/x.png"], "does not exist"),
    ),
)
def test_bad_options_exit_2_and_write_nothing(commands, request, extra, message):
    result, written = outcome(commands, request)
    assert result.returncode == 2
    assert message in result.stderr
    assert "Traceback" not in result.stderr
    assert written == []


@pytest.mark.parametrize(
    "extra",
    slow_except(
        [["--integrator", "pathh"], ["--spp", "-3"], ["--width", "x"], ["--workers", "100000"]],
        ["--spp", "-3"],
    ),
)
def test_argparse_errors_exit_2(commands, request, extra):
    result = outcome(commands, request)
    assert result.returncode == 2 and "Traceback" not in result.stderr


@pytest.mark.parametrize(
    "argv,option",
    [
        (["--spp", "1" + "0" * 5000], "--spp"),
        (["--set", "seed=" + "9" * 5000], "--set seed"),
        (["--set", "background=" + "[" * 3000], "--set background"),
    ],
)
def test_values_beyond_what_toml_reads_are_one_clear_error(tmp_path, capsys, argv, option):
    """An integer of thousands of digits or arrays nested thousands deep: Python's
    int() and tomllib refuse them with ValueError and RecursionError, which must
    not end the command with a traceback."""
    status = main(["render", "cornell", "--quiet", "-o", str(tmp_path / "x.png"), *argv])
    err = capsys.readouterr().err
    assert status == 2 and err.startswith(f"rtpy: error: {option}: expected")
    assert len(err.splitlines()) == 1 and list(tmp_path.iterdir()) == []


def test_bad_scene_file_exits_2_with_file_table_and_key(tmp_path):
    scene = write(
        tmp_path,
        '[camera]\nvfov = 40\n\n[materials.red]\ntype = "lambertian"\nalbedoo = [1, 0, 0]\n',
    )
    out = tmp_path / "out.png"
    result = run_cli("render", str(scene), "-o", str(out), "--quiet")
    assert result.returncode == 2
    assert "bad.toml" in result.stderr and "materials.red" in result.stderr
    assert "albedoo" in result.stderr and "albedo" in result.stderr
    assert "Traceback" not in result.stderr
    assert not out.exists()


def test_unknown_scene_name_exits_2(commands, request):
    result = outcome(commands, request)
    assert result.returncode == 2 and "cornell" in result.stderr


def start_render(*args: str) -> subprocess.Popen:
    return subprocess.Popen(rtpy_command("render", *args), stderr=subprocess.PIPE, text=True)


def percent_done(seen: str) -> int:
    """The share of the samples the progress bar shows finished, in percent."""
    done = re.findall(r"(\d+)%\|", seen.rsplit("\r", 1)[-1])
    return int(done[-1]) if "path" in seen and done else 0


def wait_for_exit(pid: int, timeout: float = 60) -> bool:
    """True once process pid (not necessarily our child) has ended, False if it still
    runs after timeout seconds (Linux: waits on a pidfd)."""
    try:
        fd = os.pidfd_open(pid)
    except ProcessLookupError:
        return True
    try:
        return bool(select.select([fd], [], [], timeout)[0])
    finally:
        os.close(fd)


@pytest.mark.parametrize(
    "backend,workers",
    slow_except([("scalar", "1"), ("scalar", "2"), ("numpy", "1"), ("numpy", "2")], ("numpy", "1")),
)
def test_ctrl_c_writes_the_finished_samples(tmp_path, workers, backend):
    """SIGINT to a real render once samples are finished: it stops, writes a valid
    image of the samples finished so far, says how many, and exits with 130."""
    out = tmp_path / "partial.png"
    spp = "16" if backend == "scalar" else "20000"  # scalar: 8 passes of 2 spp
    proc = start_render(
        "cornell", "--width", "48", "--spp", spp, "--workers", workers, "--backend", backend,
        "-o", str(out),
    )  # fmt: skip
    # two passes of the scalar's 8; 1% of 20000 spp is 7 of the numpy's passes of 28
    seen = read_until(proc, lambda text: percent_done(text) >= (25 if spp == "16" else 1))
    proc.send_signal(signal.SIGINT)
    _, rest = proc.communicate(timeout=60)
    assert proc.returncode == 130, seen + rest
    assert "interrupted" in rest and f"of {spp} samples per pixel" in rest
    assert "Traceback" not in rest
    with Image.open(out) as im:
        assert im.size == (48, 48)
        assert np.asarray(im).max() > 0


@pytest.mark.slow
@pytest.mark.parametrize("workers", ["1", "2"])
def test_second_ctrl_c_exits_at_once(tmp_path, workers):
    """A second SIGINT while the partial image is being written ends the process at
    once: no waiting for the write, no traceback, no worker left running, and no
    file half-written (the output is absent, and so is its temporary file).

    After the first Ctrl-C the command says on stderr that it writes the partial
    image; the second SIGINT is sent when that line is read, while this 3000x3000
    image (PNG and .npy, seconds to write) is being written; its first pass (1 spp,
    depth 1: cheap paths) must have finished for anything to be written. The naive
    handling (Python's default KeyboardInterrupt, or SIG_DFL set once the render
    returns) either prints a traceback from wherever the second signal lands, or dies
    inside the write and leaves its temporary file behind; waiting for the write
    would leave the complete files."""
    out = tmp_path / "big.png"
    proc = start_render(
        "cornell", "--width", "3000", "--spp", "8", "--max-depth", "1", "--backend", "numpy",
        "--workers", workers, "-o", str(out), "--linear", str(tmp_path / "big.npy"),
    )  # fmt: skip
    try:
        read_until(proc, lambda text: percent_done(text) >= 13)  # a pass of 1 spp finished
        ps = subprocess.run(["ps", "-o", "pid=", "--ppid", str(proc.pid)], capture_output=True)
        workers_pids = [int(p) for p in ps.stdout.split()]
        assert len(workers_pids) == (2 if workers == "2" else 0)
        proc.send_signal(signal.SIGINT)
        seen = read_until(proc, lambda text: "writing the samples finished so far" in text)
        proc.send_signal(signal.SIGINT)
        _, rest = proc.communicate(timeout=60)
        assert proc.returncode == 130, seen + rest
        assert "interrupted again" in rest and "Traceback" not in seen + rest
        # No image, no temporary file; the render's state, saved whole after the first
        # Ctrl-C, is kept for --resume.
        state = tmp_path / "big.png.resume.npz"
        assert list(tmp_path.iterdir()) in ([], [state])
        if state.exists():
            with np.load(state) as saved:
                assert saved["sums"].shape == (3000, 3000, 4) and "rtpy" in str(saved["key"])
        # the workers have ended (stopped at the first Ctrl-C, killed at the second)
        assert all(wait_for_exit(pid) for pid in workers_pids), "worker processes still running"
    finally:  # the render's state and a partial image: hundreds of MB, pass or fail
        if proc.poll() is None:  # a failed test's render
            proc.kill()
            proc.wait()
        for path in tmp_path.iterdir():
            path.unlink()


@pytest.mark.parametrize(
    "output,linear,message",
    [
        ("no/such/dir/out.png", None, "does not exist"),
        ("a_file/out.png", None, "is not a directory"),
        ("a_dir.png", None, "existing directory"),
        ("x" * 300 + ".png", None, "File name too long"),
        ("", None, "no file extension"),
        ("out.png", "a_file/out.npy", "is not a directory"),
        ("out.png", "a_dir.npy", "existing directory"),
    ],
)
def test_unwritable_output_is_reported_before_rendering(
    tmp_path, monkeypatch, capsys, output, linear, message
):
    """Output paths are checked before the render starts (CI runs as root, so
    read-only directories are not tested; a file used as a directory, a missing
    directory, a directory as the path and a name the file system refuses are).
    The naive check (does the parent exist?) lets a name too long for the file
    system through, and the render's hours are lost when the write fails."""
    (tmp_path / "a_file").write_text("not a directory")
    (tmp_path / "a_dir.png").mkdir()
    (tmp_path / "a_dir.npy").mkdir()
    before = sorted(p.name for p in tmp_path.iterdir())
    monkeypatch.chdir(tmp_path)
    rendered = []
    monkeypatch.setattr(Renderer, "render", lambda *a, **k: rendered.append(1))
    argv = ["render", "cornell", *SMALL, "-o", output]
    if linear is not None:
        argv += ["--linear", linear]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert err.startswith("rtpy: error: cannot write") and message in err
    assert rendered == []
    assert sorted(p.name for p in tmp_path.iterdir()) == before


def test_unwritable_output_real_subprocess_says_so_at_once(tmp_path):
    """As a user runs it: a 30-minute render with a bad output path fails before it
    starts (stderr holds the error and no progress bar)."""
    (tmp_path / "a_file").write_text("")
    result = run_cli(
        "render", "cornell", "--spp", "100000", "-o", str(tmp_path / "a_file" / "x.png")
    )
    assert result.returncode == 2, result.stderr
    assert result.stderr.strip().splitlines() == [
        f"rtpy: error: cannot write '{tmp_path / 'a_file' / 'x.png'}': "
        f"'{tmp_path / 'a_file'}' is not a directory"
    ]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["a_file"]


@pytest.fixture
def material_registry():
    """rtpy.materials.MATERIALS as it was before the test (a plugin adds to it)."""
    saved = dict(MATERIALS)
    yield MATERIALS
    MATERIALS.clear()
    MATERIALS.update(saved)


def test_render_with_a_student_plugin_material(tmp_path, material_registry):
    """--plugin FILE.py imports the file; its @register_material class is a scene type."""
    (tmp_path / "student.py").write_text(
        "from rtpy.materials import Lambertian, register_material\n"
        "from rtpy.vec3 import Color\n\n"
        '@register_material("half_grey")\n'
        "class HalfGrey(Lambertian):\n"
        "    def __init__(self, level: float = 0.5):\n"
        "        super().__init__(Color(level, level, level))\n"
    )
    (tmp_path / "scene.toml").write_text(
        '[render]\nintegrator = "center"\n[materials.m]\ntype = "half_grey"\nlevel = 0.25\n'
        '[[objects]]\ntype = "sphere"\ncenter = [0, 0, -1]\nradius = 0.5\nmaterial = "m"\n'
    )
    out = tmp_path / "out.npy"
    args = ["render", str(tmp_path / "scene.toml"), "--width", "8", "--quiet"]
    assert main([*args, "-o", str(tmp_path / "o.png"), "--linear", str(out)]) == 2  # unknown type
    args += ["--plugin", str(tmp_path / "student.py")]
    assert main([*args, "-o", str(tmp_path / "o.png"), "--linear", str(out)]) == 0
    assert np.load(out)[2, 4].tolist() == [0.25, 0.25, 0.25]  # the ball's center pixel
    assert main([*args[:-1], str(tmp_path / "missing.py"), "-o", str(tmp_path / "p.png")]) == 2
    assert "half_grey" in material_registry


def test_linear_exr_without_openexr_exits_2_before_rendering(tmp_path, capsys, monkeypatch):
    import sys

    monkeypatch.setitem(sys.modules, "OpenEXR", None)  # import OpenEXR fails

    def no_render(*args, **kwargs):
        raise AssertionError("rendered although the output cannot be written")

    monkeypatch.setattr(Renderer, "render", no_render)
    out, png = tmp_path / "x.exr", tmp_path / "x.png"
    status = main(["render", "cornell", *SMALL, "-o", str(png), "--linear", str(out)])
    err = capsys.readouterr().err
    assert status == 2 and err.startswith(f"rtpy: error: cannot write '{out}'")
    assert "pip install 'rtpy[exr]'" in err and len(err.splitlines()) == 1
    assert list(tmp_path.iterdir()) == []


def mesh_scene(folder: Path, obj_text: str) -> Path:
    """folder/m.toml: one Lambertian mesh read from folder/m.obj, which holds obj_text."""
    (folder / "m.obj").write_text(obj_text)
    scene = folder / "m.toml"
    scene.write_text(
        '[materials.m]\ntype = "lambertian"\n\n'
        '[[objects]]\ntype = "mesh"\npath = "m.obj"\nmaterial = "m"\n'
    )
    return scene


def test_mesh_scene_with_a_malformed_obj_exits_2_naming_file_table_key_and_line(tmp_path):
    scene = mesh_scene(tmp_path, "v 0 0 0\nv 1 0 0\nv 0 1\nf 1 2 3\n")
    out = tmp_path / "out.png"
    result = run_cli("render", str(scene), "-o", str(out), "--quiet")
    assert result.returncode == 2 and not out.exists()
    (line,) = result.stderr.splitlines()
    assert line.startswith(f"rtpy: error: {scene}: [[objects]] #1 path: ")
    assert "m.obj line 3: expected 3 to 4 numbers after 'v'" in line


def test_a_mesh_with_degenerate_faces_renders_with_a_one_line_warning(tmp_path):
    scene = mesh_scene(tmp_path, "v 0 0 -2\nv 1 0 -2\nv 0 1 -2\nv 2 0 -2\nf 1 2 3\nf 1 2 4\n")
    out = tmp_path / "out.png"
    result = run_cli("render", str(scene), "-o", str(out), "--quiet", "--width", "8", "--spp", "1")
    assert result.returncode == 0 and out.exists()
    (warning,) = [line for line in result.stderr.splitlines() if "warning" in line]
    assert warning.startswith(f"rtpy: warning: {scene}: [[objects]] #1 path: skipped 1 degenerate")
    assert "warnings.warn" not in result.stderr and "SceneWarning" not in result.stderr


def render_under(method: str, *args: str) -> subprocess.CompletedProcess:
    """`python -m rtpy render ARGS` in a child whose start method is forced to `method`
    (what `python -m rtpy` does, after multiprocessing.set_start_method)."""
    code = (
        "import multiprocessing, sys\n"
        f"multiprocessing.set_start_method({method!r})\n"
        "from rtpy.cli.main import main\n"
        "sys.exit(main(sys.argv[1:], prog='python -m rtpy'))\n"
    )
    return subprocess.run(
        [sys.executable, "-c", code, "render", *args], capture_output=True, text=True, timeout=120
    )


@pytest.mark.slow
def test_a_plugin_render_on_two_workers_is_the_same_under_every_start_method(tmp_path):
    """With its material from --plugin, a render on two workers started by spawn or
    forkserver (the defaults of Windows, macOS and Python 3.14) finishes with the
    image fork gives: the workers import the plugin under the parent's name."""
    (tmp_path / "plug.py").write_text(
        "from rtpy.materials import Lambertian, register_material\n"
        "from rtpy.vec3 import Color\n\n"
        '@register_material("tinted")\n'
        "class Tinted(Lambertian):\n"
        "    def __init__(self, level: float = 0.5):\n"
        "        super().__init__(Color(level, 0.5 * level, 0.25))\n"
    )
    (tmp_path / "scene.toml").write_text(
        '[render]\nintegrator = "path"\nspp = 4\nsky = true\n'
        '[materials.m]\ntype = "tinted"\nlevel = 0.8\n'
        '[[objects]]\ntype = "sphere"\ncenter = [0, 0, -1]\nradius = 0.5\nmaterial = "m"\n'
    )
    images = {}
    for method in ["fork", "spawn", "forkserver"]:
        out = tmp_path / f"{method}.npy"
        result = render_under(
            method, str(tmp_path / "scene.toml"), "--plugin", str(tmp_path / "plug.py"),
            "--workers", "2", "--width", "24", "-q", "-o", str(tmp_path / "o.png"),
            "--linear", str(out),
        )  # fmt: skip
        assert result.returncode == 0, result.stderr
        images[method] = np.load(out)
    assert images["fork"].max() > 0
    np.testing.assert_array_equal(images["spawn"], images["fork"])
    np.testing.assert_array_equal(images["forkserver"], images["fork"])


def test_no_command_prints_the_full_help_naming_the_program_as_run(commands, request):
    result = outcome(commands, request)
    assert result.returncode == 0 and result.stderr == ""
    assert result.stdout.startswith("usage: python -m rtpy ")
    for command in ["render", "scenes", "bench", "assignment", "grade"]:
        assert f"    {command} " in result.stdout or f"    {command}\n" in result.stdout
    assert "'python -m rtpy COMMAND --help'" in result.stdout


def test_errors_name_the_program_as_run(commands, request, capsys):
    with pytest.raises(SystemExit) as exit_:
        main(["render"], prog="rtpy")
    assert exit_.value.code == 2
    err = capsys.readouterr().err
    assert err.startswith("usage: rtpy render ") and "rtpy render: error:" in err
    result = outcome(commands, request)
    assert result.returncode == 2 and "python -m rtpy render: error:" in result.stderr


def test_version_is_the_installed_package_version(commands, request):
    from importlib.metadata import version

    result = outcome(commands, request)
    assert result.returncode == 0 and result.stdout.strip() == f"python -m rtpy {version('rtpy')}"
    assert rtpy.__version__ == version("rtpy")


def test_short_options_and_the_default_worker_count(monkeypatch):
    """-j N and -q are --workers N and --quiet; without them the workers are the CPUs
    this process may use."""
    monkeypatch.setattr("rtpy.cli.main.available_cpus", lambda: 3)
    args = build_parser().parse_args(["render", "cornell"])
    assert args.workers == 3 and not args.quiet
    args = build_parser().parse_args(["render", "cornell", "-j", "2", "-q"])
    assert args.workers == 2 and args.quiet
    monkeypatch.setattr("rtpy.cli.main.available_cpus", lambda: 10_000)
    assert build_parser().parse_args(["render", "cornell"]).workers == MAX_WORKERS


def test_workers_that_cannot_start_stop_the_render_with_one_error(tmp_path):
    """A plugin that refuses to run in a worker process: under spawn the render stops
    at once with one `rtpy: error:` line and status 1, writing nothing."""
    (tmp_path / "parent_only.py").write_text(
        "import multiprocessing\n"
        "if multiprocessing.parent_process() is not None:\n"
        "    raise RuntimeError('imported in a worker')\n"
    )
    out = tmp_path / "o.png"
    result = render_under(
        "spawn", "week08_three_balls", "--plugin", str(tmp_path / "parent_only.py"),
        "-j", "2", "--width", "160", "--spp", "1", "-q", "-o", str(out),  # 4 units of 1 spp
    )  # fmt: skip
    assert result.returncode == 1, result.stderr
    errors = [line for line in result.stderr.splitlines() if line.startswith("rtpy: error:")]
    assert len(errors) == 1 and "Traceback" not in result.stderr
    assert "(start method 'spawn') cannot rebuild the scene: PluginError:" in errors[0]
    assert "RuntimeError: imported in a worker" in errors[0]
    assert not out.exists()


def test_preview_is_written_while_rendering(tmp_path, capsys):
    out, preview = tmp_path / "out.png", tmp_path / "preview.png"
    args = ["render", "cornell", *SMALL, "--spp", "4", "-j", "1", "-q", "-o", str(out)]
    assert main([*args, "--preview", str(preview), "--preview-seconds", "0"]) == 0
    with Image.open(preview) as im, Image.open(out) as final:
        assert im.size == final.size
    assert sorted(p.name for p in tmp_path.iterdir()) == ["out.png", "preview.png"]


@pytest.mark.parametrize("same", ["out.png", "./sub/../out.png"])
def test_preview_needs_a_file_of_its_own(tmp_path, capsys, monkeypatch, same):
    monkeypatch.chdir(tmp_path)
    (tmp_path / "sub").mkdir()
    status = main(["render", "cornell", *SMALL, "-o", str(tmp_path / "out.png"),
                   "--preview", same])  # fmt: skip
    assert status == 2
    assert "--preview" in capsys.readouterr().err
    assert sorted(p.name for p in tmp_path.iterdir()) == ["sub"]


@pytest.mark.parametrize("value,status", [("0.00", 0), ("0e0", 0), ("-1", 2), ("nan", 2)])
def test_preview_seconds_from_zero(tmp_path, capsys, value, status):
    args = ["render", "cornell", *SMALL, "-j", "1", "-o", str(tmp_path / "out.png")]
    args += ["--preview", str(tmp_path / "preview.png"), "--preview-seconds", value]
    if status:
        with pytest.raises(SystemExit) as exit_:
            main(args)
        assert exit_.value.code == 2 and "expected seconds from 0" in capsys.readouterr().err
        assert list(tmp_path.iterdir()) == []
    else:
        assert main(args) == 0


# --- one value per --set, outputs that are inputs, writes that fail ----------------------
@settings(max_examples=150)
@given(
    key=st.sampled_from(sorted(SETTINGS)),
    text=st.one_of(
        st.text(),
        st.integers(-5, 10**6).map(str),
        st.sampled_from(["true", "srgb", "path", " 2.5 # c", "[0.1, 0.2, 0.3]", "{a = 1}"]),
    ),
)
def test_a_set_value_is_one_line_refusal_or_applied_as_its_toml(key, text):
    """Any text after KEY=: refused in one line naming --set KEY, or applied as the one
    TOML value it is (a bare word as itself); never a second key smuggled past."""
    try:
        overrides = checked_by_the_command_line("--set", f"{key}={text}")
    except UsageError as e:  # one terminal line (other characters shown as a scene file's)
        assert str(e).startswith(f"--set {key}") and not {"\n", "\r"} & set(str(e))
        return
    assert "\n" not in text and "\r" not in text
    try:
        value = tomllib.loads(f"v = {text}")["v"]
    except (tomllib.TOMLDecodeError, ValueError, RecursionError):
        value = text.strip()
    assert overrides == {key: SETTINGS[key].check(value)}


@settings(max_examples=40)
@given(spp=st.integers(1, 10**6), other=st.sampled_from(["width=8", "spp=1", "[render]"]))
def test_a_line_break_never_smuggles_a_second_key(spp, other):
    assert parse_set([f"spp={spp}"]) == {"spp": spp}
    for separator in ("\n", "\r\n", "\r"):
        with pytest.raises(UsageError, match=r"^--set spp: expected one value on one line"):
            parse_set([f"spp={spp}{separator}{other}"])


def test_a_second_key_in_set_or_a_flag_exits_2_before_rendering(tmp_path, capsys, monkeypatch):
    monkeypatch.setattr(Renderer, "render", lambda *a, **k: pytest.fail("rendered"))
    out = str(tmp_path / "x.png")
    for option in (["--set", "spp=4\nwidth=8"], ["--spp", "4\nwidth = 8"]):
        assert main(["render", "cornell", "--quiet", "-o", out, *option]) == 2
        err = capsys.readouterr().err
        assert err.startswith(f"rtpy: error: {option[0]}") and len(err.splitlines()) == 1
    assert list(tmp_path.iterdir()) == []


def test_an_output_that_the_render_reads_is_refused_whatever_its_extension(tmp_path, capsys):
    """The scene file named like a PNG, a texture, a plugin behind a link: exit 2,
    each input as it was."""
    (tmp_path / "planet.png").write_bytes((bundled_dir() / "planet.png").read_bytes())
    (tmp_path / "scene.png").write_text((bundled_dir() / "week07_textures.toml").read_text())
    (tmp_path / "plugin.py").write_text("")
    args = ["render", str(tmp_path / "scene.png"), *SMALL, "--plugin", str(tmp_path / "plugin.py")]
    cases = [["-o", "scene.png"], ["-o", "planet.png"], ["-o", "x.png", "--preview", "planet.png"]]
    if sys.platform != "win32":
        os.symlink(tmp_path / "plugin.py", tmp_path / "plugin.npy")
        cases.append(["-o", "x.png", "--linear", "plugin.npy"])
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    for case in cases:
        argv = [*args, *(str(tmp_path / a) if "." in a else a for a in case)]
        assert main(argv) == 2, case
        err = capsys.readouterr().err
        assert "an input" in err and len(err.splitlines()) == 1, err
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


def test_a_write_that_fails_half_way_is_one_line_exit_1_and_keeps_the_old_image(
    tmp_path, capsys, monkeypatch
):
    """The disk fills while the PNG is written: exit 1, one line naming the file and
    the reason, no temporary file, the image that was there untouched."""
    out = tmp_path / "out.png"
    out.write_bytes(b"old image")

    def half_then_full(self, fp, *args, **kwargs):
        Path(fp).write_bytes(b"\x89PNG half")
        raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

    monkeypatch.setattr(Image.Image, "save", half_then_full)
    assert main(["render", "cornell", *SMALL, "-j", "1", "-o", str(out)]) == 1
    err = capsys.readouterr().err
    assert err == f"rtpy: error: cannot write '{out}': {os.strerror(errno.ENOSPC)}\n"
    assert out.read_bytes() == b"old image" and list(tmp_path.iterdir()) == [out]


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="RLIMIT_FSIZE as on Linux")
def test_a_file_size_limit_is_one_line_exit_1_in_a_real_process(tmp_path):
    """A real limit on file size (SIGXFSZ ignored, so the write fails with EFBIG):
    exit 1, one line, no traceback, the old outputs untouched, no temporary file."""
    old = {name: b"old" for name in ("out.png", "out.npy")}
    for name, data in old.items():
        (tmp_path / name).write_bytes(data)
    code = (
        "import resource, signal, sys\n"
        "signal.signal(signal.SIGXFSZ, signal.SIG_IGN)\n"
        "resource.setrlimit(resource.RLIMIT_FSIZE, (64, 64))\n"
        "from rtpy.cli.main import main\n"
        "sys.exit(main(sys.argv[1:]))\n"
    )
    argv = ["render", "cornell", *SMALL, "-j", "1", "-o", "out.png", "--linear", "out.npy"]
    # map-tests' log of the solution regions run is a file too: the limit would stop it
    env = {k: v for k, v in os.environ.items() if k != "RTPY_REGION_LOG"}
    proc = subprocess.run(
        [sys.executable, "-c", code, *argv], cwd=tmp_path, env=env, capture_output=True,
        text=True, timeout=120,
    )  # fmt: skip
    assert proc.returncode == 1, proc.stderr
    assert re.fullmatch(
        rf"rtpy: error: cannot write 'out\.(png|npy)': {os.strerror(errno.EFBIG)}\n", proc.stderr
    )
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == old


def test_a_preview_that_cannot_be_written_stops_the_render_in_one_line(
    tmp_path, capsys, monkeypatch
):
    real = Image.Image.save

    def save(self, fp, *args, **kwargs):
        if Path(fp).name.startswith(".preview.png"):  # the temporary file of the preview
            raise OSError(errno.EIO, os.strerror(errno.EIO))
        return real(self, fp, *args, **kwargs)

    monkeypatch.setattr(Image.Image, "save", save)
    preview = tmp_path / "preview.png"
    argv = ["render", "cornell", *SMALL, "--spp", "4", "-j", "1", "-o", str(tmp_path / "out.png")]
    assert main([*argv, "--preview", str(preview), "--preview-seconds", "0"]) == 1
    state = tmp_path / "out.png.resume.npz"  # what was finished, kept
    assert capsys.readouterr().err == (
        f"rtpy: error: cannot write '{preview}': {os.strerror(errno.EIO)}; "
        f"--resume continues the render ({state})\n"
    )
    assert list(tmp_path.iterdir()) == [state]


def test_a_quiet_render_loads_no_progress_bar_and_no_other_command(tmp_path):
    out = tmp_path / "out.png"
    argv = ["render", "cornell", "--width", "4", "--spp", "1", "-j", "1", "-q", "-o", str(out)]
    loaded = modules_imported_by(f"from rtpy.cli.main import main\nmain({argv!r})")
    assert out.exists() and "numpy" in loaded
    unneeded = {"tqdm", "rtpy.cli.bench", "rtpy.grading", "importlib.metadata"}
    unneeded |= {"rtpy.testing.chi_square", "rtpy.testing.material_checks"}
    assert not loaded & unneeded


# --- time limits, resume, clusters ------------------------------------------------------

LONG = ["--width", "16", "--spp", "100000", "-j", "1", "--quiet"]  # 9 minutes of passes


def test_a_time_limit_ends_a_long_render_with_whole_passes_and_its_state(tmp_path, capsys):
    out = tmp_path / "out.npy"
    argv = ["render", "week08_three_balls", *LONG, "-o", str(tmp_path / "o.png")]
    assert main([*argv, "--linear", str(out), "--time", "0.5"]) == 0
    err = capsys.readouterr().err
    held = re.search(r"16x9, (\d+) of 100000 spp in the time limit of 0\.5 s", err)
    assert held and int(held[1]) >= 1 and "--resume continues it" in err, err
    image = np.load(out)
    assert np.isfinite(image).all() and image.max() > 0
    assert (tmp_path / "o.png.resume.npz").exists()


def test_resume_of_another_render_is_one_line_exit_2_and_keeps_every_file(tmp_path, capsys):
    argv = ["render", "week08_three_balls", *LONG, "-o", str(tmp_path / "o.png"), "--time", "0.3"]
    assert main(argv) == 0
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    capsys.readouterr()
    assert main([*argv, "--resume", "--seed", "5"]) == 2
    err = capsys.readouterr().err
    assert err == (
        f"rtpy: error: --resume: {tmp_path / 'o.png.resume.npz'}: saved with seed = 0, not 5; "
        "render without --resume to start over\n"
    )
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before
    assert main(argv) == 0  # without --resume: it starts over, and says so
    assert "rtpy: note: starting over; --resume continues the render in" in capsys.readouterr().err


@pytest.mark.slow
def test_a_render_stopped_by_its_time_limit_and_resumed_is_the_uninterrupted_one(tmp_path):
    """issue 29's check, as a user runs it: `--time`, then the same command with
    --resume, gives the image of the render never stopped, bit for bit (2 workers;
    about 3 s of rendering, stopped after half a second)."""
    args = ["render", "cornell", "--width", "24", "--spp", "32", "-j", "2", "-q"]
    full, part = tmp_path / "full.npy", tmp_path / "part.npy"
    done = run_cli(*args, "-o", str(tmp_path / "full.png"), "--linear", str(full))
    assert done.returncode == 0, done.stderr
    stop = [*args, "-o", str(tmp_path / "part.png"), "--linear", str(part)]
    stopped = run_cli(*stop, "--time", "0.5")
    held = re.search(r"(\d+) of 32 spp in the time limit", stopped.stderr)
    assert stopped.returncode == 0 and held and int(held[1]) < 32, stopped.stderr
    resumed = run_cli(*stop, "--resume")
    assert resumed.returncode == 0 and f"({held[1]} resumed)" in resumed.stderr, resumed.stderr
    np.testing.assert_array_equal(np.load(part), np.load(full))
    assert not (tmp_path / "part.png.resume.npz").exists()


@pytest.mark.parametrize(
    "extra,message",
    [
        (["--cluster", "nowhere"], '--cluster nowhere: expected "local" or a scheduler\'s'),
        (["--time", "-2"], "--time: expected a number in [0, 1000000), found -2"),
        (["--time", "soon"], "--time: expected a number"),
    ],
)
def test_bad_time_and_cluster_options_exit_2(tmp_path, capsys, extra, message):
    assert main(["render", "cornell", *SMALL, "-o", str(tmp_path / "o.png"), *extra]) == 2
    err = capsys.readouterr().err
    assert err.startswith("rtpy: error: ") and message in err and len(err.splitlines()) == 1
    assert list(tmp_path.iterdir()) == []


def test_a_cluster_without_dask_says_how_to_install_it(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "distributed", None)  # import distributed fails
    assert (
        main(["render", "cornell", *SMALL, "-o", str(tmp_path / "o.png"), "--cluster", "local"])
        == 2
    )
    err = capsys.readouterr().err
    assert (
        err
        == "rtpy: error: --cluster local: needs Dask distributed (pip install 'rtpy[cluster]')\n"
    )


@pytest.mark.parametrize(
    "address", ["tcp://127.0.0.1", "tcp://:8786", "tcp://h:x", "ws://h:8786", "tcp://h:1:2"]
)
def test_a_malformed_cluster_address_is_one_line_and_exit_2(tmp_path, capsys, address):
    pytest.importorskip("distributed")
    status = main(
        ["render", "cornell", *SMALL, "-o", str(tmp_path / "x.png"), "--cluster", address]
    )
    err = capsys.readouterr().err
    assert status == 2 and err.startswith(f"rtpy: error: --cluster {address}: expected"), err
    assert len(err.splitlines()) == 1 and list(tmp_path.iterdir()) == []


@pytest.mark.slow
def test_the_cluster_timeout_option_reaches_the_connection(tmp_path, capsys):
    """In a process of its own: Dask's client leaves a thread running in the process
    that made it (which rtpy.io.forked's tests must not inherit)."""
    pytest.importorskip("distributed")
    import socket

    with socket.socket() as s:  # a port of 127.0.0.1 where nothing listens
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    argv = ["render", "cornell", *SMALL, "-o", str(tmp_path / "x.png")]
    result = run_cli(*argv, "--cluster", f"tcp://127.0.0.1:{port}", "--cluster-timeout", "1")
    err = result.stderr
    assert result.returncode == 1 and "cannot reach the Dask scheduler" in err, err
    assert "within 1 s" in err and len(err.splitlines()) == 1 and list(tmp_path.iterdir()) == []
    with pytest.raises(SystemExit) as caught:  # argparse: seconds above 0
        main([*argv, "--cluster", "local", "--cluster-timeout", "0"])
    assert caught.value.code == 2


@pytest.mark.parametrize("gamma", ["1e-5", "5e-324"])
def test_a_tiny_gamma_writes_the_image_and_its_previews(tmp_path, capsys, gamma):
    out, preview = tmp_path / "x.png", tmp_path / "p.png"
    argv = ["render", "cornell", *SMALL, "--spp", "4", "-o", str(out), "--set", f"gamma={gamma}"]
    status = main([*argv, "--preview", str(preview), "--preview-seconds", "0"])
    err = capsys.readouterr().err
    assert status == 0 and "Traceback" not in err, err
    assert Image.open(out).size[0] == 16 and Image.open(preview).size[0] == 16


def test_an_output_name_of_255_characters_is_written(tmp_path, capsys):
    out = tmp_path / ("o" * 251 + ".png")
    status = main(["render", "cornell", *SMALL, "-o", str(out)])
    err = capsys.readouterr().err
    assert status == 0 and "Traceback" not in err, err
    assert [p.name for p in tmp_path.iterdir()] == [out.name]


@pytest.mark.parametrize(
    "plugin, words",
    [
        ("import sys\nsys.exit(0)\n", "it called sys.exit(0)"),
        ("raise ValueError('one\\ntwo')\n", "ValueError: one\\ntwo"),
        ("from rtpy.materials import register_material\nregister_material(None)\n", "TypeError"),
    ],
)
def test_a_failing_plugin_is_one_line_exit_2_nothing_written(
    tmp_path, capsys, material_registry, plugin, words
):
    (tmp_path / "student.py").write_text(plugin)
    out = tmp_path / "o.png"
    argv = ["render", "cornell", *SMALL, "-o", str(out), "--plugin", str(tmp_path / "student.py")]
    status = main(argv)
    err = capsys.readouterr().err
    assert status == 2 and err.startswith("rtpy: error: --plugin ") and words in err, err
    assert len(err.splitlines()) == 1 and not out.exists()


@pytest.mark.parametrize(
    "option, value",
    [
        ("-o", "no\nsuch/x.png"),
        ("--linear", "no\nsuch/x.npy"),
        ("--plugin", "a\nb.py"),
        ("-o", "x\r.gif"),
    ],
)
def test_a_line_break_in_a_path_is_shown_on_one_line(tmp_path, capsys, monkeypatch, option, value):
    monkeypatch.chdir(tmp_path)
    argv = ["render", "cornell", *SMALL, *(["-o", "o.png"] if option != "-o" else [])]
    status = main([*argv, option, value])
    err = capsys.readouterr().err
    assert status == 2 and len(err.splitlines()) == 1, err
    assert value.replace("\n", "\\n").replace("\r", "\\r") in err
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("option", ["-o", "--linear", "--preview"])
def test_an_empty_output_path_is_refused_for_every_output(tmp_path, capsys, monkeypatch, option):
    monkeypatch.chdir(tmp_path)
    argv = ["render", "cornell", *SMALL, *(["-o", "o.png"] if option != "-o" else [])]
    status = main([*argv, option, ""])
    err = capsys.readouterr().err
    assert status == 2 and err.startswith("rtpy: error: cannot write '': no file extension"), err
    assert list(tmp_path.iterdir()) == []
