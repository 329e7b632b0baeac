"""The student's process (rtpy.grading.child): task methods that return None or the
wrong type are named wherever they are called; where an exception was raised is found
in the task files (the judge's side of the process is tests/grading/test_sandbox.py)."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

from rtpy import Color, PointLight, Vec3
from rtpy.grading.child import (
    TaskReturnError,
    checked,
    expected_return,
    rtpy_classes,
    student_frame,
)
from rtpy.light import LightSample

ROOT = Path(__file__).resolve().parents[2]


def test_expected_return_reads_the_annotation():
    classes = rtpy_classes()
    assert expected_return(PointLight.sample, classes) == (True, [LightSample])
    assert expected_return(Vec3.length, classes) == (False, [])  # float: only None is checked

    def no_annotation():
        pass

    assert expected_return(no_annotation, classes) == (True, [])


def test_a_task_returning_none_or_the_wrong_type_is_named():
    def shade(x) -> Color:
        return x

    task = checked(shade, "Shader.shade (rtpy/shade.py)", rtpy_classes())
    assert task(Color(1, 2, 3)) == Color(1, 2, 3)
    assert task(Vec3(1, 2, 3)) == Vec3(1, 2, 3)  # Color's base class: accepted
    with pytest.raises(TaskReturnError, match=r"Shader.shade \(rtpy/shade.py\) returned None"):
        task(None)
    with pytest.raises(TaskReturnError, match="returned a value of type tuple, expected Color"):
        task((1, 2, 3))

    def maybe(x) -> LightSample | None:
        return x

    task = checked(maybe, "Light.sample", rtpy_classes())
    assert task(None) is None  # allowed
    with pytest.raises(TaskReturnError, match="returned a value of type int, expected LightSample"):
        task(3)

    def distance(x) -> float | None:
        return x

    assert checked(distance, "d", rtpy_classes()) is distance  # nothing to check


PLANTED_MISSING_RETURN = """
import rtpy.integrators.direct as direct
import rtpy.materials.blinn_phong as blinn
import rtpy.materials.phong as phong
from rtpy.grading.child import TaskReturnError, install_return_checks


def compute_scattering(self, ray, scene) -> "Color":
    self.last = ray  # the planted mistake: the result is never returned


direct.DirectIntegrator.compute_scattering = compute_scattering
original = phong.sample_cosine_power
print(install_return_checks([
    {"path": "rtpy/integrators/direct.py", "function": "DirectIntegrator.compute_scattering"},
    {"path": "rtpy/materials/phong.py", "function": "sample_cosine_power"},
]))
try:
    direct.DirectIntegrator.compute_scattering(direct, None, None)
except TaskReturnError as err:
    print(err)
print(blinn.sample_cosine_power is phong.sample_cosine_power is not original)
print(blinn.sample_cosine_power(2.0, 0.3, 0.6) == original(2.0, 0.3, 0.6))
"""


def test_a_planted_missing_return_is_named_wherever_the_method_is_called():
    """In a process of its own (the wrappers stay): the task method is wrapped where it
    is defined and in every module that imported it by name."""
    proc = subprocess.run(
        [sys.executable, "-c", PLANTED_MISSING_RETURN], capture_output=True, text=True, timeout=120
    )
    assert proc.returncode == 0, proc.stderr[-2000:]
    assert proc.stdout.splitlines() == [
        "['DirectIntegrator.compute_scattering (rtpy/integrators/direct.py)', "
        "'sample_cosine_power (rtpy/materials/phong.py)']",
        "DirectIntegrator.compute_scattering (rtpy/integrators/direct.py) returned None, "
        "expected Color: is a `return` missing?",
        "True",
        "True",
    ]


def test_the_innermost_frame_of_a_task_file_is_named(tmp_path):
    """student_frame: the innermost frame in a task file, else in rtpy/, else None."""
    code = "def sample(p):\n    return helper(p)\ndef helper(p):\n    return 1 / p\n"
    space: dict = {}
    exec(compile(code, str(tmp_path / "rtpy" / "light.py"), "exec"), space)
    try:
        space["sample"](0)
    except ZeroDivisionError as err:
        tb = err.__traceback__
    base = tmp_path.resolve()
    assert student_frame(tb, base, {"rtpy/light.py"}) == ("helper", "rtpy/light.py", 4)
    assert student_frame(tb, base, set()) == ("helper", "rtpy/light.py", 4)  # rtpy/: fallback
    assert student_frame(tb, base / "elsewhere", {"rtpy/light.py"}) is None
