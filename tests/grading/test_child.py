"""The autograder's side of the student's process (rtpy.grading.autograder_child): task
methods that return None or the wrong type are named, an exception names the
student's function, file and line, a test over its time limit is stopped and says
where it was."""

from __future__ import annotations

import json
import shutil
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from rtpy import Color, PointLight, Vec3
from rtpy.grading.autograder_child import (
    TaskReturnError,
    checked,
    describe,
    expected_return,
    rtpy_classes,
)
from rtpy.grading.autograder_submission import child_environment
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
from rtpy.grading.autograder_child import TaskReturnError, install_return_checks


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


def raise_in(code: str, filename: str):
    """The exception `code` raises, as if the code were in `filename` under ROOT."""
    try:
        exec(compile(code, str(ROOT / filename), "exec"), {})
    except BaseException as err:  # noqa: BLE001 (any exception, as pytest would see it)
        return err
    raise AssertionError("no exception")


def test_an_exception_names_the_students_function_file_and_line():
    code = "def sample(p):\n    return 1 / p\nsample(0)\n"
    err = raise_in(code, "rtpy/light.py")
    message = describe(err, ROOT, {"rtpy/light.py"}, 60)
    assert message == (
        "ZeroDivisionError: division by zero (raised in sample (rtpy/light.py, line 2))"
    )
    err = raise_in("def f():\n    raise GraderTimeout\nf()\n".replace(
        "raise GraderTimeout", "raise __import__('rtpy.grading.autograder_child', "
        "fromlist=['x']).GraderTimeout"), "rtpy/scene.py")  # fmt: skip
    message = describe(err, ROOT, {"rtpy/scene.py"}, 7)
    assert message.startswith(
        "did not finish within the 7 s time limit (it was in f (rtpy/scene.py, line 2))"
    )
    assert describe(AssertionError("PointLight.sample: wrong\nassert 1 == 2"), ROOT, set(), 1) == (
        "PointLight.sample: wrong"
    )


@pytest.mark.slow
def test_the_child_stops_an_endless_test_and_goes_on(tmp_path):
    """A planted endless loop in a task file: the test fails after the time limit,
    naming the loop's function and line; the next test still runs."""
    repo = tmp_path / "repo"
    shutil.copytree(ROOT / "rtpy", repo / "rtpy", ignore=shutil.ignore_patterns("__pycache__"))
    (repo / "tests").mkdir()
    (repo / "rtpy" / "loop.py").write_text("def spin():\n    while True:\n        pass\n")
    (repo / "tests" / "test_loop.py").write_text(
        textwrap.dedent(
            """
            from rtpy.loop import spin

            def test_spins():
                spin()

            def test_fine():
                assert True
            """
        )
    )
    config = tmp_path / "config.json"
    config.write_text(json.dumps({"test_timeout": 1, "task_files": ["rtpy/loop.py"]}))
    events = tmp_path / "events.jsonl"
    proc = subprocess.run(
        [sys.executable, "-m", "rtpy.grading.autograder_child", str(events), str(config), "tests"],
        cwd=repo, env=child_environment(repo), capture_output=True, text=True, timeout=120,
    )  # fmt: skip
    results = [json.loads(line) for line in events.read_text().splitlines()]
    outcome = {e["nodeid"]: e for e in results if e["event"] == "result"}
    assert proc.returncode == 0, proc.stderr[-2000:]
    spins = outcome["tests/test_loop.py::test_spins"]
    assert not spins["passed"]
    assert (
        "did not finish within the 1 s time limit (it was in spin (rtpy/loop.py, line"
        in (spins["output"])
    )
    assert outcome["tests/test_loop.py::test_fine"]["passed"]
