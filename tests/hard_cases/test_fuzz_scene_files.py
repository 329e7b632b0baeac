"""Broken scene files through the command line: a valid scene or one clear error.

Hypothesis takes a random valid scene (tests/hard_cases/scene_strategies.py) and
breaks it: wrong types, NaN and infinite numbers, unknown and missing keys,
references to materials and textures that do not exist, degenerate quads and
triangles of zero area, vup parallel to the view direction, zero, negative and
absurd sizes (width 10^9, spp 0, a negative radius, a 2^70 integer), tables where
values belong, and cut or garbled text. `rtpy.cli.main.main` runs in-process on the
file and must either render it (exit 0, a complete PNG) or print ONE line
`rtpy: error: FILE: [table] key: ...` and exit 2 with nothing written: never a
traceback, never a partial file. A few cases also run as real subprocesses.

Derandomized (a fixed sequence of examples) so CI is reproducible;
FUZZ_EXAMPLES=20 runs twenty times as many.
"""

from __future__ import annotations

import contextlib
import io
import math
import tempfile
from pathlib import Path

import numpy as np
import pytest
from hypothesis import event, given
from hypothesis import strategies as st
from PIL import Image

from rtpy.cli.main import main
from tests.io.scene_text import VALUES, to_toml

from ..commands import run_cli
from .scene_strategies import fuzz_settings, random_scene, seeds

SMALL = ["--width", "4", "--spp", "1", "--set", "max_depth=2", "--quiet"]

BAD_NUMBERS = [math.nan, math.inf, -math.inf, 0, 0.0, -1, -1e-300, 1e9, 10**9, 2**70, 1e308]


def _table_paths(data: dict) -> list[tuple]:
    """Paths to every table of a parsed scene: ("camera",), ("materials", "m0"),
    ("objects", 2), ..."""
    paths = []
    for name, value in data.items():
        if name in ("camera", "render"):
            paths.append((name,))
        elif isinstance(value, dict):
            paths += [(name, sub) for sub in value]
        elif isinstance(value, list):
            paths += [(name, i) for i in range(len(value))]
    return paths


def _get(data: dict, path: tuple) -> dict:
    table = data
    for part in path:
        table = table[part]
    return table


def _minus(a, b):
    return [x - y for x, y in zip(a, b, strict=True)]


@st.composite
def mutation(draw, data: dict) -> str:
    """Break `data` in place in one way; returns the kind of break (for statistics)."""
    paths = _table_paths(data)
    path = draw(st.sampled_from(paths))
    table = _get(data, path)
    kind = draw(
        st.sampled_from(
            [
                "any value",
                "bad number",
                "delete key",
                "unknown key",
                "missing reference",
                "degenerate shape",
                "vup parallel",
                "absurd size",
                "not a table",
            ]
        )
    )
    if kind == "any value":
        table[draw(st.sampled_from(sorted(table)))] = draw(VALUES)
    elif kind == "bad number":
        key = draw(st.sampled_from(sorted(table)))
        value = draw(st.sampled_from(BAD_NUMBERS))
        if isinstance(table[key], list) and table[key]:
            table[key][draw(st.integers(0, len(table[key]) - 1))] = value
        else:
            table[key] = value
    elif kind == "delete key":
        table.pop(draw(st.sampled_from(sorted(table))), None)
    elif kind == "unknown key":
        table[draw(st.sampled_from(["albedoo", "radious", "Type", "widht", "x"]))] = 1
    elif kind == "missing reference":
        for obj in data["objects"]:
            obj["material"] = draw(st.sampled_from(["nope", "m9", "M0", ""]))
        for mat in data["materials"].values():
            if "albedo" in mat:
                mat["albedo"] = "no_texture"
    elif kind == "degenerate shape":
        obj = draw(st.sampled_from(data["objects"]))
        k = draw(st.sampled_from([0.0, 1.0, -2.0, 0.5]))
        if obj["type"] == "quad":
            obj["v"] = [k * x for x in obj["u"]]
        elif obj["type"] == "triangle":
            obj["c"] = [a + k * (b - a) for a, b in zip(obj["a"], obj["b"], strict=True)]
        else:
            obj["radius"] = draw(st.sampled_from([0.0, -0.5, -1e-300]))
    elif kind == "vup parallel":
        cam = data["camera"]
        k = draw(st.sampled_from([1.0, -3.0, 1e-9, 0.0]))
        cam["vup"] = [k * x for x in _minus(cam["look_at"], cam["look_from"])]
    elif kind == "absurd size":
        name, key, value = draw(
            st.sampled_from(
                [
                    ("camera", "width", 10**9),
                    ("camera", "width", 0),
                    ("camera", "width", 16385),
                    ("camera", "aspect_ratio", 1e-9),
                    ("camera", "aspect_ratio", "1:0"),
                    ("camera", "width", 1e9),
                    ("render", "spp", 0),
                    ("render", "spp", 10**7),
                    ("render", "max_depth", 0),
                    ("render", "max_depth", 10**6),
                    ("render", "spp", -1),
                    ("camera", "vfov", 180),
                    ("camera", "focus_distance", 0),
                    ("camera", "defocus_angle", 180),
                ]
            )
        )
        data[name][key] = value
    else:  # a value where a table belongs, or the reverse
        name = draw(st.sampled_from(["camera", "render", "materials", "objects", "textures"]))
        data[name] = draw(st.sampled_from([1, "x", [1, 2], {"a": {"b": 1}}, [[1]]]))
    return kind


@st.composite
def broken_files(draw) -> tuple[str, list[str]]:
    """(TOML text, kinds of break) of a valid scene broken 1 to 3 times, sometimes
    also cut short or garbled as text."""
    data = random_scene(draw(seeds), image_path="tex.png")
    kinds = []
    for _ in range(draw(st.integers(1, 3))):
        try:
            kinds.append(draw(mutation(data)))
        except (TypeError, KeyError, IndexError, AttributeError):
            break  # an earlier break replaced a table this one needs
    text = to_toml(data)
    how = draw(st.sampled_from(["as written"] * 4 + ["cut", "garbled"]))
    if how == "cut":
        text = text[: draw(st.integers(0, len(text)))]
    elif how == "garbled":
        at = draw(st.integers(0, len(text)))
        junk = draw(st.sampled_from(["[", "]", '"', "=", "\n[[", "\x00", "\ufeff"]))
        text = text[:at] + junk + text[at:]
    if how != "as written":
        kinds.append(how)
    return text, kinds


def run_main(argv: list[str]) -> tuple[int, str]:
    """(exit status, stderr) of rtpy.cli.main.main run in this process."""
    err = io.StringIO()
    with contextlib.redirect_stderr(err), contextlib.redirect_stdout(io.StringIO()):
        try:
            status = main(argv)
        except SystemExit as e:  # argparse
            status = e.code
    return status, err.getvalue()


def check_one_clear_error(status: int, stderr: str, scene: Path, folder: Path, before: set) -> None:
    """Exit 2, one line naming the file and what is wrong, nothing written."""
    assert status == 2, stderr
    lines = stderr.strip().splitlines()
    assert len(lines) == 1, stderr
    assert lines[0].startswith(f"rtpy: error: {scene}: "), stderr
    assert "Traceback" not in stderr
    assert set(folder.iterdir()) == before, "a file was written"


@pytest.fixture(scope="module")
def texture_png(tmp_path_factory) -> Path:
    path = tmp_path_factory.mktemp("tex") / "tex.png"
    Image.fromarray(np.full((2, 2, 3), 200, np.uint8)).save(path)
    return path


@fuzz_settings(100)
@given(case=broken_files(), backend=st.sampled_from(["scalar", "numpy"]))
def test_broken_scene_file_renders_or_gives_one_clear_error(texture_png, case, backend):
    """The naive loader lets these through to the renderer, which then fails with a
    traceback deep inside (ZeroDivisionError for a zero-area quad, MemoryError for
    width 10^9) or writes an image of NaNs."""
    text, kinds = case
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        (folder / "tex.png").write_bytes(texture_png.read_bytes())
        scene = folder / "scene.toml"
        scene.write_text(text, encoding="utf-8")
        out = folder / "out.png"
        before = set(folder.iterdir())
        status, stderr = run_main(
            ["render", str(scene), *SMALL, "--backend", backend, "-o", str(out)]
        )
        if status == 0:
            event("rendered")
            with Image.open(out) as im:
                im.load()
                assert im.size[0] == 4
            assert set(folder.iterdir()) == before | {out}
            return
        event("error: " + " ".join(sorted(set(kinds))))
        check_one_clear_error(status, stderr, scene, folder, before)


CLEAR_ERRORS = [
    ("[camera]\nwidth = 1000000000\n", "[camera] width"),
    ("[camera]\nwidth = 1e9\n", "[camera] width"),
    ("[render]\nspp = 0\n", "[render] spp"),
    ("[camera]\nlook_from = [0, 0, 0]\nlook_at = [0, 1, 0]\nvup = [0, 2, 0]\n", "[camera] vup"),
    (
        '[materials.m]\ntype = "lambertian"\n[[objects]]\ntype = "quad"\n'
        'q = [0, 0, 0]\nu = [1, 0, 0]\nv = [2, 0, 0]\nmaterial = "m"\n',
        "[[objects]] #1 u",
    ),
    (
        '[materials.m]\ntype = "lambertian"\n[[objects]]\ntype = "sphere"\n'
        'center = [0, 0, 0]\nradius = nan\nmaterial = "m"\n',
        "[[objects]] #1 radius",
    ),
    # A string or key quoted in the message holds a character that splitlines and
    # terminals take for a line break (U+0085, U+2028): it is escaped.
    ('[camera]\naspect_ratio = "\u0085"\n', "[camera] aspect_ratio"),
    ('[camera]\n"wid\u2028th" = 3\n', "[camera] wid\\u2028th"),
]
# These also run as real subprocesses, as a user runs them (1-2 s each).
SUBPROCESS = {0, 3, 6}


@pytest.mark.parametrize("index", range(len(CLEAR_ERRORS)))
def test_known_bad_files_give_one_clear_error(tmp_path, index):
    """Each stderr is one line that names the file, the table and the key, the
    status is 2, and no file is written (in-process, and for a few through
    `python -m rtpy`)."""
    text, where = CLEAR_ERRORS[index]
    scene = tmp_path / "bad.toml"
    scene.write_text(text)
    argv = ["render", str(scene), "-o", str(tmp_path / "out.png"), "--quiet"]
    runs = [run_main(argv)]
    if index in SUBPROCESS:
        result = run_cli(*argv)
        runs.append((result.returncode, result.stderr))
    for status, stderr in runs:
        assert status == 2
        lines = stderr.strip().splitlines()
        assert len(lines) == 1 and lines[0].startswith(f"rtpy: error: {scene}: {where}"), lines
        assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.toml"]


def test_the_checks_reject_a_traceback_and_a_written_file(tmp_path):
    """check_one_clear_error fails on a traceback, two lines, a wrong status or a
    file left behind."""
    scene = tmp_path / "s.toml"
    scene.write_text("")
    before = set(tmp_path.iterdir())
    good = f"rtpy: error: {scene}: [camera] width: expected an integer\n"
    check_one_clear_error(2, good, scene, tmp_path, before)
    for status, stderr in [(1, good), (2, "Traceback (most recent call last):\n" + good)]:
        with pytest.raises(AssertionError):
            check_one_clear_error(status, stderr, scene, tmp_path, before)
    (tmp_path / "out.png").write_bytes(b"half")
    with pytest.raises(AssertionError):
        check_one_clear_error(2, good, scene, tmp_path, before)


OPTION_VALUES = {
    "--width": ["0", "-1", "4", "16384", "1000000000", "1e9", "x", ""],
    "--spp": ["0", "1", "2", "1000001", "nan", "-5"],
    "--max-depth": ["0", "1", "3", "501", "2.5"],
    "--seed": ["0", "-1", "99999999999999999999999", "abc"],
    "--workers": ["0", "1", "257", "-2"],
    "--integrator": ["path", "whitted", "center", "pathh", ""],
    "--backend": ["scalar", "numpy", "gpu"],
    "--set": [
        "spp=0", "spp=2", "spp=2.0", "width=16384", "width=5", "max_depth=0", "nee=maybe",
        "nee=false", "gamma=0", "gamma=nan", "gamma=inf", "background=[1e31, 0, 0]",
        "background=[0.1, 0.2]", "background=[nan, 0, 0]", "sky=true", "seed=-3",
        "integrator=direct", "bogus=1", "russian_roulette=-1", "spp", "=", "width=[1]",
    ],
    "-o": ["out.png", "out.gif", "", "missing/out.png", "out"],
    "--linear": ["out.npy", "out.pfm", "out.png", "missing/out.npy"],
}  # fmt: skip


@fuzz_settings(60)
@given(
    options=st.lists(
        st.sampled_from(sorted(OPTION_VALUES)).flatmap(
            lambda flag: st.tuples(st.just(flag), st.sampled_from(OPTION_VALUES[flag]))
        ),
        max_size=4,
    ),
    aspect=st.sampled_from(["1", "0.001", '"16:9"']),
)
def test_random_command_line_options_render_or_give_one_clear_error(
    tmp_path_factory, options, aspect
):
    """Options combine with the file: `--width 16384` with a scene's aspect ratio
    0.001 asks for an image 16 million pixels high. The naive CLI checked the
    option alone and started allocating; every combination here either renders
    (exit 0) or exits 2 with one message (argparse's usage errors included) and
    nothing written."""
    folder = tmp_path_factory.mktemp("options")
    scene = folder / "scene.toml"
    scene.write_text(f"[camera]\nwidth = 4\naspect_ratio = {aspect}\n")
    argv = ["render", str(scene), "--quiet", "--spp", "1"]
    for flag, value in options:
        if flag in ("-o", "--linear") and value:
            value = str(folder / value)
        argv += [flag, value]
    if not any(flag == "-o" for flag, _ in options):
        argv += ["-o", str(folder / "default.png")]
    before = set(folder.iterdir())
    status, stderr = run_main(argv)
    assert status in (0, 2), stderr
    assert "Traceback" not in stderr
    if status == 2:
        assert set(folder.iterdir()) == before, argv
        assert stderr.strip().splitlines()[-1].count("error") >= 1, stderr
        event("error")
    else:
        event("rendered")
