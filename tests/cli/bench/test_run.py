"""rtpy.cli.bench.run: the levels of a series, their seeds, a time budget and Ctrl-C.

render_once is replaced by a stand-in whose images and timings the test chooses (the
reference's image plus noise shrinking as 1/sqrt(spp)), so what is checked does not
depend on how fast the machine is; tests/cli/bench/test_command.py runs the real thing."""

from __future__ import annotations

import numpy as np
import pytest

import rtpy.cli.bench.run as run
from rtpy.cli.bench.run import render_once, run_bench, run_series
from rtpy.cli.bench.scenes import load_bench_scene

SCENE = "plane_point_light"


class FakeRenders:
    """render_once's stand-in: records each call's spp and seed, takes `unit` seconds
    per sample per pixel row, and raises KeyboardInterrupt at the call `interrupt_at`."""

    def __init__(self, ref, unit: float = 0.001, interrupt_at: int | None = None) -> None:
        self.ref, self.unit, self.interrupt_at = ref, unit, interrupt_at
        self.calls: list[tuple[int, int]] = []

    def __call__(self, bs, backend, variant, spp, seed, workers, sampler="independent"):
        if len(self.calls) == self.interrupt_at:
            raise KeyboardInterrupt
        self.calls.append((spp, seed))
        noise = np.random.default_rng(seed).normal(0.0, 0.1, self.ref.image.shape)
        return self.ref.image + noise / np.sqrt(spp), self.unit * spp, 10.0


@pytest.fixture
def bench_scene():
    bs = load_bench_scene(SCENE, width=8)
    return bs, bs.reference_for(bs.max_depth)


def test_each_render_of_a_series_has_its_own_seed(monkeypatch, bench_scene):
    bs, ref = bench_scene
    fake = FakeRenders(ref)
    monkeypatch.setattr(run, "render_once", fake)
    levels = run_series(bs, "numpy", "path-mis", (1, 4, 16), None, 3, 1, ref, log=str, seed=7)
    assert [lv.spp for lv in levels] == [1, 4, 16]
    assert [spp for spp, _ in fake.calls] == [1, 1, 1, 4, 4, 4, 16, 16, 16]
    assert [seed for _, seed in fake.calls] == [7, 8, 9, 1007, 1008, 1009, 2007, 2008, 2009]
    assert all(lv.repeats == 3 and lv.seconds == pytest.approx(0.001 * lv.spp) for lv in levels)
    # the error falls as 1/spp, as the stand-in's noise does
    assert levels[0].mse > 8 * levels[2].mse > 0


def test_a_budget_doubles_spp_while_the_next_level_is_predicted_to_fit(monkeypatch, bench_scene):
    """Each level costs repeats * spp * 1 ms and the next is predicted to cost twice
    this one: with 2 repeats and 50 ms, levels 1, 2, 4 and 8 have spent 30 ms, and
    16 (another 32 ms) would not fit."""
    bs, ref = bench_scene
    monkeypatch.setattr(run, "render_once", FakeRenders(ref))
    levels = run_series(bs, "numpy", "path-mis", None, 0.05, 2, 1, ref, log=str)
    assert [lv.spp for lv in levels] == [1, 2, 4, 8]
    # However small the budget, a series has two levels: a slope needs them.
    levels = run_series(bs, "numpy", "path-mis", None, 1e-9, 2, 1, ref, log=str)
    assert [lv.spp for lv in levels] == [1, 2]


def test_ctrl_c_keeps_the_levels_measured_so_far(monkeypatch, bench_scene):
    """KeyboardInterrupt in the middle of the second series: the first series and the
    finished levels of the second are kept, each with its fit, and the run says so."""
    _, ref = bench_scene
    monkeypatch.setattr(run, "render_once", FakeRenders(ref, interrupt_at=2 * 3 + 2 * 2))
    variants = ("path-mis", "path-brdf")
    result = run_bench([SCENE], ("numpy",), variants, (1, 4, 16), repeats=2, width=8, log=str)
    assert result.interrupted
    measured = [(lv.integrator, lv.spp) for lv in result.levels]
    assert measured == [(variants[0], s) for s in (1, 4, 16)] + [(variants[1], s) for s in (1, 4)]
    assert [(f.integrator, f.levels) for f in result.fits] == [("path-mis", 3), ("path-brdf", 2)]


def test_render_once_measures_a_real_render_and_refuses_an_interrupted_one(monkeypatch):
    bs = load_bench_scene(SCENE, width=8)
    image, seconds, peak = render_once(bs, "numpy", "path-mis", 2, seed=1, workers=1)
    assert image.shape == (bs.camera.height, 8, 3) and seconds > 0 and peak > 0

    class Interrupted:
        interrupted = True
        linear = image

    monkeypatch.setattr("rtpy.render", lambda *args, **kwargs: Interrupted())
    with pytest.raises(KeyboardInterrupt):
        render_once(bs, "numpy", "path-mis", 2, seed=1, workers=1)
