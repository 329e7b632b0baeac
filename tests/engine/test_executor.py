"""rtpy.engine.executor: the loop runs units through any executor, and the image does not
depend on which or on the order units come back in."""

from __future__ import annotations

import numpy as np
import pytest

import rtpy
from rtpy.engine.executor import Executor, InProcess, WorkerError

from .test_renderer import small_scene


class Backwards(Executor):
    """Renders the units it is given, and gives them back in the reverse order."""

    name = "backwards"
    workers = 3

    def run(self, backend, units, timeout=None):
        render_one = backend.start()
        done = [(unit, render_one(unit)) for unit in units]
        yield None  # nothing finished yet: the loop looks at the clock and goes on
        yield from reversed(done)


@pytest.mark.slow
def test_any_executor_gives_the_same_image():
    scene, camera = small_scene()
    camera = camera.with_width(100)  # 100 x 56: 2, 2, 3 and 2 units a pass
    settings = scene.settings or rtpy.RenderSettings(spp=5, seed=4)
    here = rtpy.Renderer(scene, camera, settings).render()
    backwards = rtpy.Renderer(scene, camera, settings, executor=Backwards()).render()
    np.testing.assert_array_equal(backwards.linear, here.linear)
    assert backwards.stats["executor"] == "backwards" and backwards.stats["workers"] == 3
    assert here.stats["executor"] == InProcess.name


def test_in_process_starts_the_backend_once_and_renders_in_order():
    started, seen = [], []

    class Backend:
        def start(self):
            started.append(1)
            return lambda unit: seen.append(unit) or unit

    units = list(range(5))
    results = list(InProcess().run(Backend(), iter(units)))
    assert started == [1] and seen == units and [u for u, _ in results] == units


def test_a_worker_error_is_a_runtime_error():
    assert issubclass(WorkerError, RuntimeError)
