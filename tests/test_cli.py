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
