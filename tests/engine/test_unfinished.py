"""rtpy.engine.unfinished: a render that reaches a task's stub stops with one line
naming the task, the method and its file, and the integrators that render now."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

import rtpy
from rtpy.engine import renderer
from rtpy.engine.unfinished import find_unfinished, stub_message, working_integrators
from rtpy.grading.assignment import Region

from ..commands import rtpy_command, run_cli

STUB = Region(Path("rtpy/materials/phong.py"), 0, 1, "08", "the lobe", "Phong.BRDF", "    ")


def stub_error(region: Region = STUB, task: str | None = "8.1") -> NotImplementedError:
    """The error the stub rtpy.grading.assignment writes for `region` raises."""
    code = "".join(line.strip() for line in region.stub(task)[1:])
    try:
        exec(code)
    except NotImplementedError as err:
        return err
    raise AssertionError("the stub raised nothing")


def test_a_stub_is_read_back_task_method_and_file():
    found = find_unfinished(stub_error())
    assert (found.week, found.task, found.function) == ("08", "8.1", "Phong.BRDF")
    assert found.file == "rtpy/materials/phong.py"
    assert found.describe().startswith(
        "task 8.1 is not written yet: Phong.BRDF in rtpy/materials/phong.py"
    )
    bare = find_unfinished(stub_error(task=None))  # a stub that does not say its task
    assert bare.describe().startswith("a week-08 task is not written yet: Phong.BRDF")


def test_only_a_stub_is_one_and_it_is_found_through_the_chain():
    assert find_unfinished(NotImplementedError()) is None
    assert find_unfinished(NotImplementedError("subclasses implement this")) is None
    assert find_unfinished(ValueError("week08 task: Phong.BRDF: x")) is None
    outer = RuntimeError("a worker failed")
    outer.__cause__ = stub_error()
    assert find_unfinished(outer).task == "8.1"


class HalfWritten(rtpy.Lambertian):
    """A material whose BRDF and scattering are a task's stub (albedo is given): the
    flat-colour integrators render it, the lit ones reach the stub."""

    def BRDF(self, *args):
        raise stub_error()

    def scattering(self, *args):
        raise stub_error()


def half_written_scene() -> rtpy.Scene:
    ball = rtpy.Sphere(rtpy.Vec3(0, 0, -1), 0.5, HalfWritten())
    return rtpy.Scene([ball], sky=True, camera=rtpy.Camera(width=32))


def test_the_integrators_that_do_not_reach_the_stub_are_the_ones_that_work():
    scene = half_written_scene()
    settings = rtpy.RenderSettings(integrator="path")
    expected = ["shading", "jittered", "center"]  # no light: shading calls no BRDF
    assert working_integrators(scene, scene.camera, settings, "path") == expected
    assert working_integrators(rtpy.Scene([], sky=True), scene.camera, settings) == [
        "path",
        "direct",
        "whitted",
        "shading",
        "jittered",
        "center",
    ]


@pytest.mark.parametrize("workers", [1, 2])
def test_rtpy_render_stops_with_one_line_in_this_process_and_in_workers(workers, monkeypatch):
    started = []

    class Recorded(renderer.WorkerProcesses):
        def __init__(self, n: int) -> None:
            started.append(n)
            super().__init__(n)

    monkeypatch.setattr(renderer, "WorkerProcesses", Recorded)
    with pytest.raises(NotImplementedError) as info:
        rtpy.render(half_written_scene(), spp=2, workers=workers)  # 2 units: 2 workers
    assert started == ([2] if workers == 2 else [])
    message = str(info.value)
    assert "\n" not in message
    assert message.startswith("week08 task: Phong.BRDF: the lobe (task 8.1")  # graders read it
    assert message.endswith(
        "; this scene renders now with integrator='shading' (or jittered, center)"
    )
    assert info.value.__cause__ is None and info.value.__suppress_context__


def test_a_stub_before_the_render_says_nothing_renders():
    line = stub_message(stub_error())
    assert line.endswith("raised NotImplementedError; nothing renders before it is written")
    assert stub_message(NotImplementedError("abstract")) is None


PLUGIN = """
import rtpy
from rtpy.materials import Lambertian, register_material


@register_material("half_written")
class HalfWritten(Lambertian):
    def BRDF(self, *args):
        raise NotImplementedError(
            "week08 task: HalfWritten.BRDF: f_r (task 8.1, rtpy/materials/phong.py; see README)"
        )

    scattering = BRDF
"""
SCENE = """
[camera]
width = 32
[render]
spp = 2
[materials.m]
type = "half_written"
[[objects]]
type = "sphere"
center = [0, 0, -1]
radius = 0.5
material = "m"
"""


@pytest.mark.parametrize("workers", ["1", "2"])
def test_the_command_line_says_one_line_exits_2_and_writes_nothing(tmp_path, workers):
    (tmp_path / "half.py").write_text(PLUGIN)
    (tmp_path / "half.toml").write_text(SCENE)
    run = run_cli("render", "half.toml", "--plugin", "half.py", "-q", "-j", workers, cwd=tmp_path)
    assert run.returncode == 2, run.stderr
    assert run.stderr.splitlines() == [
        "rtpy: error: task 8.1 is not written yet: HalfWritten.BRDF in rtpy/materials/phong.py "
        "raised NotImplementedError; this scene renders now with --integrator shading "
        "(or jittered, center)"
    ]
    assert sorted(p.name for p in tmp_path.iterdir()) == ["half.py", "half.toml"]


def test_without_q_the_progress_bar_is_cleared_before_the_line(tmp_path):
    """What a terminal shows (each line from its last carriage return): the one line."""
    (tmp_path / "half.py").write_text(PLUGIN)
    (tmp_path / "half.toml").write_text(SCENE)
    command = rtpy_command("render", "half.toml", "--plugin", "half.py", "-j", "1")
    run = subprocess.run(command, capture_output=True, cwd=tmp_path, timeout=120)  # bytes: \r kept
    assert run.returncode == 2, run.stderr
    shown = [line.rsplit("\r", 1)[-1] for line in run.stderr.decode().split("\n")]
    assert [line for line in shown if line.strip()] == [
        "rtpy: error: task 8.1 is not written yet: HalfWritten.BRDF in rtpy/materials/phong.py "
        "raised NotImplementedError; this scene renders now with --integrator shading "
        "(or jittered, center)"
    ]
