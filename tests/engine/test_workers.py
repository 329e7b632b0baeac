"""Tests for rtpy.engine.workers: renders on worker processes under every start method, the
one error when they cannot start, and the CPUs a render may use."""

from __future__ import annotations

import multiprocessing
import os
import pickle
import subprocess
import sys

import numpy as np
import pytest

import rtpy
import rtpy.engine.workers
from rtpy.engine.workers import available_cpus

from .test_renderer import small_scene


def test_workers_give_the_same_image_under_every_start_method(start_method):
    scene, camera = small_scene()
    one = rtpy.render(scene, camera=camera, spp=4, seed=3)
    two = rtpy.render(scene, camera=camera, spp=4, seed=3, workers=2)
    np.testing.assert_array_equal(one.linear, two.linear)


@pytest.mark.skipif(sys.platform == "win32", reason="Windows cannot fork")
@pytest.mark.parametrize("start_method", ["fork"], indirect=True)
def test_forked_workers_start_from_a_parent_that_gave_back_its_freed_memory(
    monkeypatch, start_method
):
    workers_then = []
    monkeypatch.setattr(
        rtpy.engine.workers,
        "give_back_freed_memory",
        lambda: workers_then.append(len(multiprocessing.active_children())),
    )
    scene, camera = small_scene()
    rtpy.render(scene, camera=camera, spp=2, workers=2)
    assert workers_then == [0]  # once, before the first worker


# A program run in its own interpreter with the start method forced: a worker that
# cannot start must stop it at once with one message (a pool that restarts workers
# would hang it until the timeout, which only ends such a child).
WORKER_PROGRAM = """
import multiprocessing, os, sys
import rtpy
from rtpy import Camera, Lambertian, Scene, Sphere, Vec3
from rtpy.engine.workers import WorkerError

class Exits(Lambertian):
    def __reduce__(self):  # rebuilt in a worker, it ends the worker
        return (os._exit, (3,))

def local_material():
    class Local(Lambertian):
        pass
    return Local()

if __name__ == "__main__":
    multiprocessing.set_start_method(sys.argv[1])
    material = {"main": Lambertian, "exits": Exits, "local": local_material}[sys.argv[2]]()
    if sys.argv[2] == "main":  # a class the parent has in __main__ and a worker does not
        material.__class__ = type("NotInWorkers", (Lambertian,), {"__module__": "__main__"})
        setattr(sys.modules["__main__"], "NotInWorkers", material.__class__)
    scene = Scene([Sphere(Vec3(0, 0, -1), 0.5, material)])
    camera = Camera(Vec3(0, 0, 0), Vec3(0, 0, -1), width=32)
    try:
        rtpy.render(scene, camera=camera, spp=2, workers=2)
    except WorkerError as err:
        print(err)
        sys.exit(5)
    print("rendered")
"""


def run_worker_program(tmp_path, method: str, case: str) -> subprocess.CompletedProcess:
    program = tmp_path / "program.py"
    program.write_text(WORKER_PROGRAM)
    return subprocess.run(
        [sys.executable, str(program), method, case], capture_output=True, text=True, timeout=120
    )


@pytest.mark.parametrize(
    "case,reason",
    [
        ("main", "Can't get attribute 'NotInWorkers'"),
        ("exits", "ended abruptly: it was killed, ran out of memory or failed while starting"),
        ("local", "Can't pickle local object"),
    ],
)
@pytest.mark.parametrize("method", ["spawn", "forkserver"])
@pytest.mark.slow
def test_a_scene_the_workers_cannot_rebuild_stops_with_one_message(tmp_path, method, case, reason):
    result = run_worker_program(tmp_path, method, case)
    assert result.returncode == 5, result.stdout + result.stderr
    message = result.stdout.strip()
    assert f"(start method '{method}')" in message
    assert reason in message.splitlines()[0] and len(message.splitlines()) == 1
    assert "--plugin FILE.py" in message and "one worker" in message


def test_under_fork_workers_inherit_the_classes_of_main(tmp_path):
    result = run_worker_program(tmp_path, "fork", "main")
    assert result.returncode == 0 and result.stdout.strip() == "rendered", result.stderr


def test_available_cpus_is_what_this_process_may_use(monkeypatch):
    """os.process_cpu_count (Python 3.13+) first, then the affinity mask, then the
    machine's count, and 1 when the system says nothing."""
    monkeypatch.setattr(os, "process_cpu_count", lambda: 3, raising=False)
    assert available_cpus() == 3
    monkeypatch.delattr(os, "process_cpu_count")
    monkeypatch.setattr(os, "sched_getaffinity", lambda pid: {0, 5}, raising=False)
    monkeypatch.setattr(os, "cpu_count", lambda: 64)
    assert available_cpus() == 2
    monkeypatch.delattr(os, "sched_getaffinity")
    assert available_cpus() == 64  # Windows and macOS before 3.13
    monkeypatch.setattr(os, "cpu_count", lambda: None)
    assert available_cpus() == 1


def _signal_handlers() -> tuple:
    import signal

    return signal.getsignal(signal.SIGINT), signal.getsignal(signal.SIGTERM)


def test_a_worker_ignores_ctrl_c_and_ends_at_once_on_sigterm():
    """The parent alone handles Ctrl-C (the terminal sends it to the whole group) and
    ends the workers with SIGTERM: a worker ignores SIGINT and keeps SIGTERM's default
    action, whatever handlers the parent had when it forked."""
    import multiprocessing
    import signal
    from concurrent.futures import ProcessPoolExecutor

    from rtpy.engine.scalar_backend import ScalarBackend
    from rtpy.engine.workers import _init_worker
    from rtpy.render_settings import RenderSettings

    backend = ScalarBackend(*small_scene(), RenderSettings())
    previous = signal.signal(signal.SIGTERM, lambda *_: None)  # as the CLI's, inherited
    try:
        context = multiprocessing.get_context()
        payload = backend if context.get_start_method() == "fork" else pickle.dumps(backend)
        with ProcessPoolExecutor(
            1, mp_context=context, initializer=_init_worker, initargs=({}, payload)
        ) as pool:
            handlers = pool.submit(_signal_handlers).result(timeout=120)
    finally:
        signal.signal(signal.SIGTERM, previous)
    assert handlers == (signal.SIG_IGN, signal.SIG_DFL)
