"""Renderer: the one loop for any backend and executor: determinism across worker
counts, Ctrl-C and time limits keeping whole passes, previews, the progress bar."""

from __future__ import annotations

import re
import signal
import sys

import numpy as np
import pytest

import rtpy
from rtpy import Camera, Color, DiffuseLight, Lambertian, Metal, Scene, Sphere, Vec3
from rtpy.engine import signals
from rtpy.engine.backend import Backend
from rtpy.engine.executor import InProcess
from rtpy.engine.plan import Plan
from rtpy.engine.renderer import Renderer
from rtpy.render_settings import RenderSettings


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

    def plan(self, width, height, spp):
        return Plan(width, height, spp, 8 * width)  # at 1 spp, bands of 8 rows

    def start(self):
        return lambda unit: np.full(
            (unit.y1 - unit.y0, unit.x1 - unit.x0, 3), unit.region * unit.spp
        )


@pytest.mark.parametrize("workers", [1, 2])
def test_the_loop_drives_any_backend(workers):
    """Counting's sample is its unit's region, so a pixel's mean is the mean of its
    regions over the passes: passes of 1, 1 and 2 spp in bands of 8, 8 and 4 rows."""
    scene, camera = small_scene()  # 40 x 22
    settings = rtpy.RenderSettings(spp=4)
    renderer = Renderer(scene, camera, settings, workers, backend=Counting(scene, camera, settings))
    image = renderer.render()
    rows = np.arange(image.height)[:, None]
    expected = (rows // 8 + rows // 8 + 2 * (rows // 4)) / 4 * np.ones(image.width)
    np.testing.assert_array_equal(image.linear, np.repeat(expected[..., None], 3, axis=2))
    assert image.stats["backend"] == "counting" and image.samples_min == image.samples_max == 4
    assert image.stats["workers"] == workers and image.stats["passes"] == 3


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


def test_ctrl_c_keeps_the_whole_passes_the_image_of_fewer_samples():
    """Ctrl-C half-way through the third pass (of 1, 1, 2, 4 spp): the image of the
    first two, the same samples in every pixel (no black holes), bit for bit the
    render of 2 spp."""
    scene, camera = small_scene()
    sphere = InterruptAfter(calls=10**12)  # counts its intersection tests
    scene.add_object(sphere)

    def tests_made(spp: int) -> tuple[int, np.ndarray]:
        sphere.calls = 10**12
        image = rtpy.render(scene, camera=camera, spp=spp, seed=1)
        return 10**12 - sphere.calls, image.linear

    two, two_spp = tests_made(2)
    four, _ = tests_made(4)
    sphere.calls = (two + four) // 2  # in the third pass, which holds 2 spp
    image = rtpy.render(scene, camera=camera, spp=8, seed=1)
    pixels = camera.width * camera.height
    assert image.interrupted and image.stats["stopped"] == "interrupted"
    assert image.samples_min == image.samples_max == 2
    assert image.stats["paths"] == pixels * 2 < image.stats["paths_rendered"] + pixels * 2
    assert (image.linear.sum(axis=2) > 0).all() and np.isfinite(image.linear).all()
    np.testing.assert_array_equal(image.linear, two_spp)


def test_more_workers_than_units_start_no_idle_process(monkeypatch):
    """An image of one unit renders in this process whatever the worker count."""
    scene, camera = small_scene()
    monkeypatch.setattr("rtpy.engine.renderer.WorkerProcesses", None)  # calling it would fail
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
    more samples than the one before, every pixel within one pass of the others, and
    the final image is the one rendered without previews."""
    scene, camera = small_scene()
    previews = []
    image = rtpy.render(scene, camera=camera, spp=8, seed=3, preview=previews.append,
                        preview_seconds=0)  # fmt: skip
    plan = Plan(camera.width, camera.height, 8, 4096)
    assert len(previews) == plan.count_units() - 1
    paths = [p.stats["paths"] for p in previews]
    assert paths == sorted(set(paths)) and paths[-1] < image.stats["paths"]
    for p in previews:
        assert p.interrupted and p.samples_max - p.samples_min <= max(plan.passes)
        assert np.isfinite(p.linear).all()
    alone = rtpy.render(scene, camera=camera, spp=8, seed=3)
    np.testing.assert_array_equal(image.linear, alone.linear)
    assert not image.interrupted
    # Pass k of 8 spp draws what pass k of any spp that has it draws: the preview
    # holding k whole passes is the image of their samples.
    for k in (1, 2, 4):
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


# --- time limit -------------------------------------------------------------------------


class Clock:
    """A perf_counter that moves one second each time it is read: the loop reads it
    at the start and after each unit, so the time limit is met after a known unit."""

    def __init__(self) -> None:
        self.now = 0.0

    def perf_counter(self) -> float:
        self.now += 1.0
        return self.now


@pytest.mark.parametrize("limit,samples", [(2.5, 4), (1e-6, 1)])
def test_a_time_limit_keeps_whole_passes_at_least_one(monkeypatch, limit, samples):
    """40 x 22 at 8 spp: one unit per pass (1, 1, 2, 4 spp), one second each on the
    clock. A limit of 2.5 s ends after the third pass, one of a microsecond after the
    first: the image of that many samples, bit for bit, not interrupted."""
    scene, camera = small_scene()
    monkeypatch.setattr("rtpy.engine.renderer.time", Clock())
    image = rtpy.render(scene, camera=camera, spp=8, seed=5, time=limit)
    assert image.samples_min == image.samples_max == samples and image.spp == 8
    assert image.stats["stopped"] == "time limit" and not image.interrupted
    monkeypatch.undo()
    fewer = rtpy.render(scene, camera=camera, spp=samples, seed=5)
    np.testing.assert_array_equal(image.linear, fewer.linear)


def test_time_is_the_time_limit_setting():
    scene, camera = small_scene()
    image = rtpy.render(scene, camera=camera.with_width(8), spp=2, time_limit=1e5)
    assert image.samples_min == 2 and image.stats["stopped"] is None
    with pytest.raises(ValueError, match="time and time_limit are one setting"):
        rtpy.render(scene, camera=camera, time=1, time_limit=2)
    with pytest.raises(
        ValueError, match=re.escape("time_limit: expected a number in [0, 1000000)")
    ):
        rtpy.render(scene, camera=camera, time=-1)


class SignalledAtTheEnd(InProcess):
    """This process, with a signal sent to it while the executor is closed (as the
    workers are ended after the last pass)."""

    def __init__(self, signum: int) -> None:
        self.signum = signum

    def run(self, backend, units, timeout=None):
        try:
            yield from super().run(backend, units, timeout)
        finally:
            signal.raise_signal(self.signum)
            for _ in range(1000):  # bytecodes where a handler would run
                pass


class SignallingBar:
    """A progress bar that sends `signum` when it is told the last path is done: the
    moment right after the last unit's sums are added."""

    def __init__(self, total: int, signum: int) -> None:
        self.left, self.signum = total, signum

    def update(self, n: int) -> None:
        self.left -= n
        if self.left == 0:
            signal.raise_signal(self.signum)

    def close(self) -> None:
        pass


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
@pytest.mark.parametrize("moment", ["last unit added", "workers ended"])
@pytest.mark.parametrize("signum", [signal.SIGINT, signal.SIGTERM])
def test_a_signal_once_the_last_pass_is_in_returns_the_finished_image(moment, signum, monkeypatch):
    """Under the command line's handlers, a first signal after the last unit's sums
    are in (while the workers are ended) is recorded: the render returns its
    finished image, which the command writes, then exits with the signal's status."""
    monkeypatch.setattr(signals, "_received", [])
    scene, camera = small_scene()
    expected = rtpy.render(scene, camera=camera, spp=4, seed=1).linear
    executor = SignalledAtTheEnd(signum) if moment == "workers ended" else InProcess()
    settings = RenderSettings(spp=4, seed=1)
    renderer = Renderer(
        scene, camera, settings, quiet=moment != "last unit added", executor=executor
    )
    monkeypatch.setattr(renderer, "_progress_bar", lambda total, done: SignallingBar(total, signum))
    with signals.stop_on_signals():
        try:
            image = renderer.render(then_write=True)
        except KeyboardInterrupt:  # (pytest would take it for the user's, and stop)
            pytest.fail("the finished render was interrupted")
        assert signals.received() == signum
        with pytest.raises(KeyboardInterrupt):  # the next render stops at once
            renderer.render()
    assert image.stats["stopped"] is None and image.samples_min == 4
    np.testing.assert_array_equal(image.linear, expected)


@pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")
def test_a_signal_at_the_end_of_a_render_not_written_next_stops_the_command(monkeypatch):
    """A command that goes on after a render (bench) stops when it returns: the
    signal recorded while the workers were ended is raised then. A Ctrl-C that
    stopped the render is not raised again: its image holds the whole passes."""
    monkeypatch.setattr(signals, "_received", [])
    scene, camera = small_scene()
    settings = RenderSettings(spp=4, seed=1)
    renderer = Renderer(scene, camera, settings, executor=SignalledAtTheEnd(signal.SIGINT))
    with signals.stop_on_signals():
        with pytest.raises(KeyboardInterrupt):
            renderer.render()
    monkeypatch.setattr(signals, "_received", [])
    stopping = InterruptAfter(calls=3000)
    scene.add_object(stopping)
    with signals.stop_on_signals():
        image = Renderer(scene, camera, settings).render()
    assert image.stats["stopped"] == "interrupted"


def test_the_readmes_scene_built_in_code_renders_as_written():
    """README.md's `rtpy.Scene([rtpy.Sphere(...)], sky=True)`: no camera given, the
    default one sees the ball in the middle of the image and the sky around it."""
    ball = rtpy.Scene([rtpy.Sphere(rtpy.Vec3(0, 0, -1), 0.5, rtpy.Lambertian())], sky=True)
    image = rtpy.render(ball, width=16, spp=1, integrator="center")
    assert (image.width, image.height) == (16, 9)
    middle, corner = image.linear[4, 8], image.linear[0, 0]
    assert np.allclose(middle, 0.5)  # Lambertian's default albedo, the center integrator
    assert corner[2] > corner[0]  # the sky: bluer than red
