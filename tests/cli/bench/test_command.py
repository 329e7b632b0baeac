"""`python -m rtpy bench`: it runs end to end and its files parse, bad options
exit 2 with nothing written, and Ctrl-C keeps the levels measured."""

from __future__ import annotations

import csv
import errno
import json
import os
import sys

import pytest

from rtpy.cli.bench import command, report
from rtpy.cli.bench.convergence import BenchResult
from rtpy.cli.bench.scenes import VARIANTS
from rtpy.cli.main import main
from rtpy.io.image import atomic_write

from ...commands import read_until, rtpy_command


def read_outputs(out):
    with (out / "bench.csv").open() as f:
        rows = list(csv.DictReader(f))
    doc = json.loads((out / "bench.json").read_text())
    return rows, doc


@pytest.mark.slow
def test_quick_bench_runs_end_to_end_and_its_files_parse(tmp_path, capsys, monkeypatch):
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # as if not installed
    out, cache = tmp_path / "out", tmp_path / "cache"
    args = ["bench", "--quick", "plane_sky_band", "week05_point_light"]
    args += ["--backends", "numpy,scalar", "--out", str(out), "--cache", str(cache)]
    assert main(args) == 0
    captured = capsys.readouterr()
    rows, doc = read_outputs(out)
    assert len(rows) == 2 * 2 * len(VARIANTS) * 3  # scenes x backends x variants x spp
    assert {r["scene"] for r in rows} == {"plane_sky_band", "week05_point_light"}
    assert {r["integrator"] for r in rows} == set(VARIANTS)
    for r in rows:
        assert float(r["seconds"]) > 0 and float(r["paths_per_second"]) > 0
        assert float(r["peak_mb"]) > 0 and float(r["rel_mse"]) >= 0
        assert r["significant"] in ("True", "False")
    assert len(doc["levels"]) == len(rows) and len(doc["fits"]) == 2 * 2 * len(VARIANTS)
    assert doc["settings"]["spp"] == [1, 4, 16] and doc["settings"]["width"] == 16
    assert doc["settings"]["machine"]["cores"] >= 1 and doc["settings"]["machine"]["python"]
    assert all(isinstance(f["slope"], float) for f in doc["fits"])
    assert "relMSE" in captured.out and "slope: of log MSE" in captured.out
    assert captured.err.count("matplotlib is not installed") == 1
    assert not (out / "bench.png").exists()
    assert list(cache.glob("week05_point_light-w16-d*.npz"))


@pytest.mark.slow
def test_bench_plot_is_drawn_when_matplotlib_is_installed(tmp_path):
    pytest.importorskip("matplotlib")
    out = tmp_path / "out"
    args = ["bench", "--quick", "furnace", "plane_point_light", "--integrators", "path-mis"]
    assert main([*args, "--out", str(out)]) == 0
    assert (out / "bench.png").stat().st_size > 1000


@pytest.mark.parametrize(
    "args,message",
    [
        (["--backends", "gpu"], "--backends"),
        (["--integrators", "path-mis,bogus"], "--integrators"),
        (["--samplers", "sobol,halton"], "--samplers"),
        (["--spp", "1,x"], "--spp"),
        (["--repeats", "1"], "--repeats"),
        (["--repeats", "0"], "--repeats: at least 2"),
        (["--width", "0"], "--width: expected"),
        (["no_such_scene"], "no_such_scene"),
    ],
)
def test_bad_bench_options_exit_2_and_write_nothing(tmp_path, capsys, args, message):
    out = tmp_path / "out"
    assert main(["bench", "--quick", *args, "--out", str(out)]) == 2
    err = capsys.readouterr().err
    assert message in err and "Traceback" not in err
    assert not out.exists()


@pytest.mark.slow
def test_ctrl_c_keeps_the_levels_measured(tmp_path):
    """SIGINT to a real bench: it stops, writes the levels finished so far, exits 130."""
    import signal
    import subprocess

    out = tmp_path / "out"
    args = ["bench", "plane_sky_band", "--spp", "1,2,4,8,100000", "--width", "16"]
    parent_handler = signal.getsignal(signal.SIGINT)
    proc = subprocess.Popen(
        rtpy_command(*args, "--out", str(out)),
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
        # a child inherits an ignored SIGINT; make sure Ctrl-C reaches it as in a shell
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),
    )
    seen = read_until(proc, lambda text: "spp 8:" in text)
    # Level 8 is recorded before its line is printed; from here on, wherever the
    # signal lands (between levels or inside the render of 100000 spp), the run
    # stops with the levels 1, 2, 4 and 8.
    proc.send_signal(signal.SIGINT)
    try:
        stdout, rest = proc.communicate(timeout=60)
    except subprocess.TimeoutExpired:
        proc.kill()
        stdout, rest = proc.communicate()
        raise AssertionError(
            f"no exit after SIGINT (parent's handler {parent_handler}): {seen}"
        ) from None
    assert proc.returncode == 130, seen + rest
    assert "interrupted" in rest
    rows, doc = read_outputs(out)
    assert doc["interrupted"] is True
    assert [int(r["spp"]) for r in rows] == [1, 2, 4, 8]
    assert doc["fits"][0]["levels"] == 4 and "relMSE" in stdout


@pytest.mark.parametrize("option", ["--out", "--cache"])
def test_an_output_folder_at_or_under_a_file_is_refused_before_measuring(
    tmp_path, capsys, monkeypatch, option
):
    monkeypatch.setattr(command, "run_bench", lambda **kwargs: pytest.fail("measured"))
    (tmp_path / "file").write_text("")
    for out in (tmp_path / "file", tmp_path / "file" / "sub"):
        assert main(["bench", "--quick", option, str(out)]) == 2
        err = capsys.readouterr().err
        assert err == f"rtpy: error: {option} {out}: {tmp_path / 'file'} is not a folder\n"
    assert [p.name for p in tmp_path.iterdir()] == ["file"]


def test_a_full_disk_after_measuring_is_one_line_exit_1_and_keeps_the_old_files(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    monkeypatch.setattr(command, "run_bench", lambda **kwargs: BenchResult())
    out = tmp_path / "out"
    out.mkdir()
    (out / "bench.csv").write_text("old")

    def full_disk(path, write):
        def half(tmp):
            tmp.write_text("half")
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))

        return atomic_write(path, half)

    monkeypatch.setattr(report, "atomic_write", full_disk)
    assert main(["bench", "--quick", "--out", str(out)]) == 1
    err = capsys.readouterr().err
    assert err == f"rtpy: error: cannot write '{out / 'bench.csv'}': {os.strerror(errno.ENOSPC)}\n"
    assert [p.name for p in out.iterdir()] == ["bench.csv"]
    assert (out / "bench.csv").read_text() == "old"
