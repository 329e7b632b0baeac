"""Renderer: work units, determinism across worker counts, interrupted renders, and the
one loop that drives any backend."""

from __future__ import annotations

import math
import re
import sys

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

import rtpy
from rtpy import Camera, Color, DiffuseLight, Lambertian, Metal, Scene, Sphere, Vec3
from rtpy.renderer import (
    MAX_BATCHES,
    MAX_PASS_SPP,
    Backend,
    PixelSums,
    Renderer,
    plan_bands,
    plan_units,
)


@pytest.mark.parametrize("width,height,spp", [(1, 1, 1), (16, 16, 16), (37, 21, 5), (40, 3, 64)])
def test_units_cover_every_pixel_with_exactly_spp_samples(width, height, spp):
    counts = np.zeros((height, width), dtype=int)
    for unit in plan_units(width, height, spp):
        counts[unit.y0 : unit.y1, unit.x0 : unit.x1] += unit.spp
    np.testing.assert_array_equal(counts, spp)


@given(st.integers(1, 300), st.integers(1, 60), st.integers(1, 200), st.integers(1, 5000))
def test_bands_cover_every_pixel_once_per_batch_within_the_path_budget(
    width, height, spp, paths_per_unit
):
    units = plan_bands(width, height, spp, paths_per_unit)
    counts = np.zeros((height, width), dtype=int)
    regions: dict[int, set] = {}
    for unit in units:
        counts[unit.y0 : unit.y1, unit.x0 : unit.x1] += unit.spp
        assert (unit.x1 - unit.x0) * (unit.y1 - unit.y0) * unit.spp <= paths_per_unit
        regions.setdefault(unit.batch, set()).add((unit.region, unit.x0, unit.y0, unit.x1, unit.y1))
    np.testing.assert_array_equal(counts, spp)
    assert len({frozenset(r) for r in regions.values()}) == 1  # the same regions every batch
    assert [u.batch for u in units] == sorted(u.batch for u in units)
    # As few passes as hold `wanted` samples per pixel each: enough to fill a unit, and
    # at least spp / MAX_BATCHES up to MAX_PASS_SPP, within the budget
    fill = paths_per_unit // (width * height)
    longer = min(math.ceil(spp / MAX_BATCHES), MAX_PASS_SPP, paths_per_unit)
    wanted = min(spp, max(1, fill, longer))
    assert len(regions) == math.ceil(spp / wanted)


@pytest.mark.parametrize(
    "width,height,spp,passes,pass_spp,bands",
    [
        (1920, 1080, 1, 1, 1, 32),  # more pixels than a unit holds paths: 1 spp
        (256, 256, 64, 8, 8, 8),  # an eighth of the samples a pass: 8 x 8192 pixels
        (256, 256, 4096, 256, 16, 16),  # at most 16 a pass: 16 x 4096 pixels
        (48, 48, 20000, 715, 28, 1),  # a small image: 28 spp fill a unit of 2304 pixels
    ],
)
def test_bands_as_docs_numpy_backend_describes_them(width, height, spp, passes, pass_spp, bands):
    """docs/numpy-backend.md's examples and test_cli's Ctrl-C render, counted by hand, for
    units of 65,536 paths."""
    units = plan_bands(width, height, spp, 65536)
    assert len({u.batch for u in units}) == passes
    assert max(u.spp for u in units) == pass_spp
    assert len({u.region for u in units}) == bands


def test_units_run_batch_by_batch():
    """Every tile gets its first batch before any tile gets a second one, so an
    interrupted render covers the whole image."""
    batches = [u.batch for u in plan_units(64, 48, 16)]
    assert batches == sorted(batches)


def small_scene() -> tuple[Scene, Camera]:
    scene = Scene(
        [
            Sphere(Vec3(0, -100.5, -1), 100, Lambertian(Color(0.5, 0.5, 0.5))),
            Sphere(Vec3(0, 0, -1), 0.5, Metal(Color(0.8, 0.6, 0.2), 0.3)),
            Sphere(Vec3(0, 1.5, -1), 0.3, DiffuseLight(Color(4, 4, 4))),
        ],
        sky=True,
    )
    return scene, Camera(Vec3(0, 0.3, 1), Vec3(0, 0, -1), vfov=60, width=40)


def test_same_seed_same_image_for_any_worker_count():
    scene, camera = small_scene()
    one = rtpy.render(scene, camera=camera, spp=4, seed=9, workers=1)
    two = rtpy.render(scene, camera=camera, spp=4, seed=9, workers=2)
    np.testing.assert_array_equal(one.linear, two.linear)
    other_seed = rtpy.render(scene, camera=camera, spp=4, seed=10, workers=1)
    assert not np.array_equal(one.linear, other_seed.linear)


def test_render_reports_samples_speed_and_memory():
    scene, camera = small_scene()
    image = rtpy.render(scene, camera=camera, spp=3)
    assert (image.samples_min, image.samples_max, image.spp) == (3, 3, 3)
    assert image.stats["paths"] == camera.width * camera.height * 3
    assert image.stats["paths_per_second"] > 0 and image.stats["peak_rss_mb"] > 0
    assert image.stats["backend"] == "scalar"
    assert not image.interrupted


def test_an_unknown_backend_is_refused():
    scene, camera = small_scene()
    with pytest.raises(ValueError, match="backend must be one of scalar, .*got 'cuda'"):
        Renderer(scene, camera, rtpy.RenderSettings(), backend="cuda")


class Counting(Backend):
    """A backend whose every sample is the index of its unit's tile: the loop alone
    decides what the image holds."""

    name = "counting"

    def uses_center_ray(self) -> bool:
        return False  # no integrator at all

    def plan_units(self, width, height, spp):
        return plan_units(width, height, spp, tile=8)

    def start(self):
        return lambda unit: np.full(
            (unit.y1 - unit.y0, unit.x1 - unit.x0, 3), unit.region * unit.spp
        )


@pytest.mark.parametrize("workers", [1, 2])
def test_the_loop_drives_any_backend(workers):
    scene, camera = small_scene()  # 40 x 22: tiles of 8 x 8, five per row
    renderer = Renderer(scene, camera.with_width(40), rtpy.RenderSettings(spp=5), workers)
    renderer.backend = Counting(scene, camera, renderer.settings)
    image = renderer.render()
    tile = np.arange(image.height)[:, None] // 8 * 5 + np.arange(image.width)[None, :] // 8
    np.testing.assert_array_equal(image.linear, np.repeat(tile[..., None], 3, axis=2))
    assert image.stats["backend"] == "counting" and image.samples_min == image.samples_max == 5


class InterruptAfter(Sphere):
    """A sphere that simulates Ctrl-C after a number of intersection tests."""

    def __init__(self, calls: int) -> None:
        super().__init__(Vec3(0, 0, -50), 1.0, Lambertian())
        self.calls = calls

    def hit_t(self, ray, t_min, t_max):
        self.calls -= 1
        if self.calls == 0:
            raise KeyboardInterrupt
        return super().hit_t(ray, t_min, t_max)


def test_ctrl_c_keeps_finished_samples():
    scene, camera = small_scene()
    pixels = camera.width * camera.height
    scene.add_object(InterruptAfter(calls=pixels * 8))  # about a quarter of the work
    image = rtpy.render(scene, camera=camera, spp=8, seed=1)
    assert image.interrupted
    assert 1 <= image.samples_min < 8
    assert image.samples_max < 8
    assert image.stats["paths"] < pixels * 8
    # Every pixel holds some finished samples: no black holes in the image.
    assert (image.linear.sum(axis=2) > 0).all()
    assert np.isfinite(image.linear).all()


def test_pixel_sums_do_not_depend_on_the_order_units_arrive_in():
    """Workers finish units in any order; PixelSums adds each tile's batches in batch
    order, so the image is bit for bit the same (adding in arrival order is not:
    float addition is not associative), and a unit is kept only until it is added.
    At every moment each pixel has the same samples, give or take one pass (a batch
    of 1 spp here)."""
    units = plan_units(40, 20, 6)
    rng = np.random.default_rng(1)
    sums = [rng.random((u.y1 - u.y0, u.x1 - u.x0, 3)) * 10.0 ** rng.integers(-8, 8) for u in units]
    in_order, shuffled = PixelSums(40, 20, 6), PixelSums(40, 20, 6)  # 6 tiles
    naive = np.zeros((20, 40, 3))
    for unit, s in zip(units, sums, strict=True):
        in_order.add(unit, s)
    for i in rng.permutation(len(units)):
        shuffled.add(units[i], sums[i])
        u = units[i]
        naive[u.y0 : u.y1, u.x0 : u.x1] += sums[i]
        assert shuffled.counts.max() - shuffled.counts.min() <= 1
    assert not shuffled._waiting and not in_order._waiting  # everything added
    np.testing.assert_array_equal(shuffled.total, in_order.total)
    np.testing.assert_array_equal(shuffled.counts, np.full((20, 40), 6))
    assert not np.array_equal(naive, in_order.total[..., :3])


def test_pixel_sums_after_ctrl_c_drop_the_units_that_wait():
    """A unit waits for an earlier batch of its region, or while it would put its
    region more than a pass ahead of another; after Ctrl-C they are dropped."""
    units = plan_units(32, 16, 3)  # two tiles, batches 0, 1, 2
    acc = PixelSums(32, 16, 2)
    ones = np.ones((16, 16, 3))
    acc.add(units[0], ones)  # tile 0, batch 0
    acc.add(units[2], ones)  # tile 0, batch 1: two passes ahead of tile 1: waits
    acc.add(units[5], ones)  # tile 1, batch 2: its batches 0 and 1 are not there
    assert acc.passes == 0 and len(acc._waiting) == 2
    acc.add(units[1], ones)  # tile 1, batch 0: pass 0 finished, tile 0's batch 1 added
    assert acc.passes == 1 and list(acc._waiting) == [(1, 2)]
    acc.finish()
    assert not acc._waiting
    np.testing.assert_array_equal(acc.counts[:, :16], 2)
    np.testing.assert_array_equal(acc.counts[:, 16:], 1)


def interrupt_at(opcode: int):
    """A tracer raising KeyboardInterrupt (a Ctrl-C's) before the opcode-th bytecode
    that PixelSums' own methods execute, counting from 1."""
    seen = 0

    def tracer(frame, event, arg):
        nonlocal seen
        if event == "call":
            if frame.f_code.co_qualname.split(".")[0] != "PixelSums":
                return None
            frame.f_trace_opcodes = True
            return tracer
        if event == "opcode":
            seen += 1
            if seen == opcode:
                raise KeyboardInterrupt
        return tracer

    return tracer


def test_pixel_sums_keep_every_sum_with_its_count_whatever_bytecode_ctrl_c_cuts():
    """Ctrl-C raises KeyboardInterrupt between any two bytecodes, also inside
    PixelSums.add; after it, each pixel's sum must be that of as many batches as its
    count says, and every count within a pass of the others. Batch b of 1 spp adds
    2**b, so a sum names the batches in it."""
    units = plan_units(32, 16, 3)  # 2 tiles x batches 0, 1, 2
    order = [units[i] for i in (0, 3, 1, 5, 4, 2)]  # tile 0: batch 2 before batch 1
    for opcode in range(1, 10_000):
        acc = PixelSums(32, 16, 2)
        sys.settrace(interrupt_at(opcode))
        try:
            for unit in order:
                acc.add(unit, np.full((unit.y1 - unit.y0, unit.x1 - unit.x0, 3), 2.0**unit.batch))
        except KeyboardInterrupt:
            interrupted = True
        else:
            interrupted = False
        finally:
            sys.settrace(None)
        acc.finish()
        counts = [[int(b).bit_count() for b in row] for row in acc.total[..., 0]]
        np.testing.assert_array_equal(acc.counts, counts, err_msg=f"cut at bytecode {opcode}")
        assert acc.counts.max() - acc.counts.min() <= 1, f"cut at bytecode {opcode}"
        if not interrupted:
            assert opcode > 100 and (acc.counts == 3).all()  # every cut was tried
            break


def test_more_workers_than_units_start_no_idle_process(monkeypatch):
    """An image of one unit renders in this process whatever the worker count."""
    scene, camera = small_scene()
    monkeypatch.setattr("rtpy.renderer.run_on_workers", None)  # calling it would fail
    image = rtpy.render(scene, camera=camera.with_width(8), integrator="center", workers=4)
    assert image.samples_min == 1


# --- progress bar ---------------------------------------------------------------------


@pytest.mark.parametrize(
    "options,shown",
    [({}, False), ({"progress": True}, True), ({"quiet": False}, True), ({"quiet": True}, False)],
)
def test_progress_bar_only_when_asked_for(capsys, options, shown):
    scene, camera = small_scene()
    rtpy.render(scene, camera=camera.with_width(8), integrator="center", **options)
    err = capsys.readouterr().err
    assert ("path" in err) == shown, err


def test_the_bar_is_tqdms_notebook_aware_one():
    import tqdm.auto

    scene, camera = small_scene()
    bar = rtpy.Renderer(scene, camera, scene.settings or rtpy.RenderSettings())._progress_bar(4)
    bar.close()
    assert isinstance(bar, tqdm.auto.tqdm)


@pytest.mark.parametrize(
    "options,error,message",
    [
        ({"progress": "yes"}, TypeError, "progress must be True or False, got 'yes'"),
        ({"quiet": 0}, TypeError, "quiet must be True or False, got 0"),
        ({"progress": True, "quiet": True}, ValueError, "progress=True contradicts quiet=True"),
    ],
)
def test_bad_progress_options_are_refused(options, error, message):
    scene, camera = small_scene()
    with pytest.raises(error, match=re.escape(message)):
        rtpy.render(scene, camera=camera, **options)


def test_previews_are_whole_frames_that_sharpen_and_leave_the_image_alone():
    """With preview_seconds=0 a preview follows every unit but the last: each holds
    more samples than the one before, every pixel within one pass of the others
    (batches are passes), and the final image is the one rendered without previews."""
    scene, camera = small_scene()
    previews = []
    image = rtpy.render(scene, camera=camera, spp=8, seed=3, preview=previews.append,
                        preview_seconds=0)  # fmt: skip
    units = plan_units(camera.width, camera.height, 8)
    assert len(previews) == len(units) - 1
    paths = [p.stats["paths"] for p in previews]
    assert paths == sorted(set(paths)) and paths[-1] < image.stats["paths"]
    for p in previews:
        assert p.interrupted and p.samples_max - p.samples_min <= 1  # 8 passes of 1 spp
        assert np.isfinite(p.linear).all()
    alone = rtpy.render(scene, camera=camera, spp=8, seed=3)
    np.testing.assert_array_equal(image.linear, alone.linear)
    assert not image.interrupted
    # Batch b of 8 draws what batch b of any spp >= b + 1 draws: the preview holding
    # k whole passes is the image of k spp.
    for k in (1, 2):
        whole = [p for p in previews if p.samples_min == p.samples_max == k][0]
        fewer = rtpy.render(scene, camera=camera, spp=k, seed=3)
        np.testing.assert_array_equal(whole.linear, fewer.linear)


def test_previews_at_most_every_preview_seconds():
    scene, camera = small_scene()
    previews = []
    rtpy.render(scene, camera=camera, spp=2, preview=previews.append, preview_seconds=1e6)
    assert previews == []


@pytest.mark.parametrize(
    "kwargs,error",
    [({"preview": 3}, TypeError), ({"preview_seconds": -1.0}, ValueError),
     ({"preview_seconds": "5"}, ValueError)],
)  # fmt: skip
def test_preview_arguments_are_checked(kwargs, error):
    scene, camera = small_scene()
    with pytest.raises(error, match="preview"):
        rtpy.render(scene, camera=camera, spp=1, **kwargs)
