"""`python -m rtpy ladder`: the strip of every rung written, every bad input refused in
one line with exit status 2 and nothing written."""

from __future__ import annotations

import pytest
from PIL import Image

from rtpy.cli.main import main
from rtpy.io.ladder import GAP, LABEL_HEIGHT

SMALL = ["--backend", "numpy", "--width", "16", "--spp", "1", "-j", "1", "-q"]


def test_ladder_writes_one_strip_of_five_labelled_panels(tmp_path, capsys):
    out = tmp_path / "ladder.png"
    assert main(["ladder", "week06_ladder", "-o", str(out), *SMALL]) == 0
    with Image.open(out) as strip:
        assert strip.size == (5 * 16 + 4 * GAP, LABEL_HEIGHT + 9)
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith(f"rtpy: wrote {out}: 5 rungs")


@pytest.mark.parametrize(
    "options,message",
    [
        (["--integrator", "path"], "--integrator: the ladder sets it"),
        (["--set", "shadows=true"], "--set shadows: the ladder sets it"),
        (["--spp", "0"], "--spp: expected an integer"),
        (["--set", "roulette_probability=0"], "--set roulette_probability: expected a number"),
        (["--set", "nope=1"], "--set nope: not a render setting"),
        (["-o", "{tmp}/ladder.txt"], "unsupported extension '.txt'"),
        (["-o", "{tmp}/missing/ladder.png"], "does not exist"),
        (["--width", "many"], "--width: expected an integer"),
    ],
)
def test_bad_input_is_one_line_and_exit_2(tmp_path, capsys, options, message):
    options = [o.replace("{tmp}", str(tmp_path)) for o in options]
    argv = ["ladder", "week06_ladder", *SMALL, *options]
    if "-o" not in options:
        argv += ["-o", str(tmp_path / "ladder.png")]
    assert main(argv) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and err[0].startswith("rtpy: error: ") and message in err[0], err
    assert list(tmp_path.iterdir()) == []


def test_an_unknown_scene_is_one_line_and_exit_2(tmp_path, capsys):
    assert main(["ladder", str(tmp_path / "nope.toml"), *SMALL]) == 2
    err = capsys.readouterr().err.splitlines()
    assert len(err) == 1 and "nope.toml" in err[0]
