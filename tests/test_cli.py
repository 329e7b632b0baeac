"""`python -m rtpy`: rendering, overrides, listing, exit codes, Ctrl-C."""

from __future__ import annotations

import os
import signal
import subprocess
import sys
import time
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

import rtpy
from rtpy.bundled import bundled_scenes
from rtpy.cli import main
from rtpy.image import read_pfm

SMALL = ["--width", "16", "--spp", "1", "--quiet"]


def run_cli(*args: str, timeout: float = 120) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-m", "rtpy", *args], capture_output=True, text=True, timeout=timeout
    )


def test_scenes_lists_every_bundled_scene_with_its_description():
    result = run_cli("scenes")
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


def write(tmp_path: Path, text: str) -> Path:
    path = tmp_path / "bad.toml"
    path.write_text(text)
    return path


@pytest.mark.parametrize(
    "extra,message",
    [
        (["--set", "bogus=1"], "bogus"),
        (["--set", "spp=0"], "spp"),
        (["--set", "background=[1, 2]"], "background"),
        (["--set", "nee"], "KEY=VALUE"),
        (["-o", "no/such/dir/x.png"], "does not exist"),
        (["-o", "x.gif"], ".gif"),
        (["--linear", "x.png"], "x.png"),
    ],
)
def test_bad_options_exit_2_and_write_nothing(tmp_path, monkeypatch, extra, message):
    monkeypatch.chdir(tmp_path)
    result = run_cli("render", "week08_three_balls", *SMALL, *extra)
    assert result.returncode == 2
    assert message in result.stderr
    assert "Traceback" not in result.stderr
    assert list(tmp_path.iterdir()) == []


@pytest.mark.parametrize("extra", [["--integrator", "pathh"], ["--spp", "-3"], ["--width", "x"]])
def test_argparse_errors_exit_2(extra):
    result = run_cli("render", "week08_three_balls", *extra)
    assert result.returncode == 2 and "Traceback" not in result.stderr


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


def test_unknown_scene_name_exits_2():
    result = run_cli("render", "cornel")
    assert result.returncode == 2 and "cornell" in result.stderr


@pytest.mark.parametrize("workers", ["1", "2"])
def test_ctrl_c_writes_the_finished_samples(tmp_path, workers):
    """SIGINT to a real render: it stops, writes a valid image of the samples
    finished so far, says how many, and exits with 130."""
    out = tmp_path / "partial.png"
    proc = subprocess.Popen(
        [
            sys.executable,
            "-m",
            "rtpy",
            "render",
            "cornell",
            "--width",
            "48",
            "--spp",
            "256",
            "--workers",
            workers,
            "-o",
            str(out),
        ],
        stderr=subprocess.PIPE,
        text=True,
    )
    # Wait until the first samples are done (the progress bar shows a count).
    deadline = time.monotonic() + 60
    seen = ""
    while time.monotonic() < deadline:
        seen += os.read(proc.stderr.fileno(), 4096).decode()
        if "path" in seen and "0/" not in seen.rsplit("\r", 1)[-1]:
            break
    time.sleep(1.0)
    proc.send_signal(signal.SIGINT)
    _, rest = proc.communicate(timeout=60)
    assert proc.returncode == 130, seen + rest
    assert "interrupted" in rest and "of 256 samples per pixel" in rest
    with Image.open(out) as im:
        assert im.size == (48, 48)
        assert np.asarray(im).max() > 0


def test_render_with_a_student_plugin_material(tmp_path):
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
