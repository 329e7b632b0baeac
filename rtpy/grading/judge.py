"""The judge: runs a week's graders (pytest tests) in the instructor's process.

A grader is a pytest test in `assignments/weekNN/test_weekNN.py` (or hidden/) that
takes the `probe` fixture: `probe.NAME(**inputs)` asks the student's process to run
the probe NAME (rtpy.grading.probes, assignments/weekNN/probes.py) and returns its
answer, checked against the probe's declared form; everything else the test does, its
assertions above all, is the verdict, made here. The student's code is never imported
in this process (the probes are imported for their forms only, from the instructor's
copy).

`Judge` is the pytest plugin: it collects each test's points, task, name and whether
it is a hidden check; gives each test `test_timeout` seconds (its probes get what is
left, and never more than what is left of `total_timeout`), stops starting tests once
`total_timeout` is spent (they are marked not run); and records an Outcome per test
with the message the student reads. `judge()` runs it.
"""

from __future__ import annotations

import sys
import time
import traceback
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest

from .protocol import ProtocolError, check
from .sandbox import ChildFailure, StudentError

HIDDEN_PART = "/hidden/"
DEFAULT_POINTS = 1.0


@dataclass
class Outcome:
    passed: bool
    output: str
    renders: bool = False  # it rendered (a failed render points to the failed components)


@dataclass
class Graded:
    """One collected test: what the results need of it."""

    nodeid: str
    name: str  # the first line of its docstring, with a parametrized case's id
    max_score: float  # its points
    task: str | None  # the id of the task of the week's map it grades ("05.1")
    hidden: bool
    outcome: Outcome | None = None


def probe_registry(probe_modules: list[Path]) -> dict:
    """The probes (with their forms) of rtpy.grading.probes and the given modules,
    imported from the instructor's copy."""
    from .probes import load_probes

    return load_probes(probe_modules)


class Probes:
    """The `probe` fixture of one test: probe.NAME(**inputs) is the checked answer of
    the probe NAME."""

    def __init__(self, judge: Judge, nodeid: str) -> None:
        self._judge, self._nodeid = judge, nodeid

    def __getattr__(self, name: str):
        if name.startswith("_"):
            raise AttributeError(name)
        found = self._judge.registry.get(name)
        if found is None:
            raise AttributeError(f"no probe called {name!r}")

        def call(**inputs):
            return self._judge.ask(self._nodeid, found, inputs)

        return call


@dataclass(eq=False)
class Judge:
    """pytest plugin: the graders' points and outcomes (see the module docstring).

    runner: a sandbox.Child (or InProcess) that answers the probes."""

    runner: object
    registry: dict
    test_timeout: float = 60.0
    total_timeout: float = 1e9
    collect_only: bool = False
    progress: object = None  # called after each test's outcome (results saved as they come)
    started: float | None = None  # time.monotonic() the total time counts from (else now)
    tests: dict[str, Graded] = field(default_factory=dict)
    errors: list[str] = field(default_factory=list)  # graders that could not be loaded
    log: list[str] = field(default_factory=list)  # for the instructor
    renders: set[str] = field(default_factory=set)  # the tests that rendered
    _deadline: float = 0.0
    _total_deadline: float = 0.0

    def pytest_configure(self, config) -> None:
        config.addinivalue_line("markers", "points(n, task): points a grader test is worth")
        started = self.started if self.started is not None else time.monotonic()
        self._total_deadline = started + self.total_timeout

    def ask(self, nodeid: str, found, inputs: dict):
        seconds = self._deadline - time.monotonic()
        if seconds <= 0.0:
            raise ChildFailure(self.late())
        if found.renders:
            self.renders.add(nodeid)
        value = self.runner.call(found.name, inputs, seconds, found.returns)
        where = f"the answer of the probe {found.name}"
        for many in ("cases", "seeds"):  # one answer per case, one render per seed
            asked = inputs.get(many)
            if isinstance(asked, list | tuple) and not (
                isinstance(value, list | np.ndarray) and len(value) == len(asked)
            ):
                wanted = f"one answer for each of {len(asked)} {many}"
                raise ProtocolError(f"{where}: expected {wanted}")
        return check(found.returns, value, where)

    # --- collection ---------------------------------------------------------------
    def pytest_collectreport(self, report) -> None:
        if report.failed:
            crash = getattr(report.longrepr, "reprcrash", None)
            text = crash.message if crash is not None else str(report.longrepr)
            self.errors.append(f"{report.nodeid}: {text.strip()}")

    def pytest_collection_modifyitems(self, items) -> None:
        for item in items:
            mark = item.get_closest_marker("points")
            doc = (getattr(item.function, "__doc__", None) or "").strip().splitlines()
            name = doc[0] if doc else item.name
            if "[" in item.name:
                name += item.name[item.name.index("[") :]
            self.tests[item.nodeid] = Graded(
                item.nodeid,
                name,
                float(mark.args[0]) if mark else DEFAULT_POINTS,
                mark.kwargs.get("task") if mark else None,
                HIDDEN_PART in f"/{item.nodeid}",
            )

    # --- running ------------------------------------------------------------------
    @pytest.hookimpl(tryfirst=True)
    def pytest_runtest_protocol(self, item, nextitem):
        if time.monotonic() > self._total_deadline:
            self.tests[item.nodeid].outcome = Outcome(False, f"not run: {self.total_limit()}")
            return True  # not run
        self._deadline = min(time.monotonic() + self.test_timeout, self._total_deadline)
        return None

    def total_limit(self) -> str:
        return f"the time limit of {self.total_timeout:g} s for the whole submission was reached"

    def late(self) -> str:
        """Why a test's probe is not asked: its time or the submission's is spent."""
        if time.monotonic() >= self._total_deadline:
            return f"stopped: {self.total_limit()}"
        return f"did not finish within {self.test_timeout:g} s"

    @pytest.hookimpl(hookwrapper=True)
    def pytest_runtest_makereport(self, item, call):
        report = (yield).get_result()
        graded = self.tests.get(item.nodeid)
        if graded is None or (graded.outcome is not None and not graded.outcome.passed):
            return  # the first failure (setup before teardown) is the one shown
        renders = item.nodeid in self.renders
        if report.failed or report.skipped:
            graded.outcome = Outcome(False, self.message(call, report, item.nodeid), renders)
        elif call.when == "call":
            graded.outcome = Outcome(True, "", renders)
        if self.progress is not None:
            self.progress()

    def message(self, call, report, nodeid: str) -> str:
        """What the student reads for a test that did not pass."""
        exc = call.excinfo.value if call.excinfo is not None else None
        if report.skipped:
            reason = report.longrepr[-1] if isinstance(report.longrepr, tuple) else ""
            return f"skipped: {reason}"
        if isinstance(exc, StudentError | ChildFailure):
            text = str(exc)
        elif isinstance(exc, AssertionError):
            text = str(exc).split("\nassert ")[0].strip() or "failed"
        elif isinstance(exc, ProtocolError):
            text = f"the student's code answered in the wrong form: {exc}"
        else:  # the grader's own failure: not the student's
            self.log.append(f"{nodeid}:\n{''.join(traceback.format_exception(exc))}")
            text = (
                f"the grader failed ({type(exc).__name__}: {exc}); this is not your code: "
                "tell your instructor"
            )
        return text if call.when == "call" else f"({call.when}) {text}"


def pytest_args(paths: list[str], collect_only: bool = False) -> list[str]:
    return [
        "-q",
        "-p",
        "no:cacheprovider",
        "--tb=no",
        "-o",
        "addopts=",
        "--continue-on-collection-errors",
        *(["--collect-only"] if collect_only else []),
        *paths,
    ]


def judge(plugin: Judge, paths: list[str]) -> Judge:
    """Run the graders at paths (files or folders) with the plugin, quietly."""
    import contextlib
    import io

    if sys.flags.optimize:
        raise RuntimeError("the graders assert: run the judge without python -O")
    with contextlib.redirect_stdout(io.StringIO()):
        pytest.main(pytest_args(paths, plugin.collect_only), plugins=[plugin])
    return plugin


def probes_outside_pytest(runner, registry: dict, seconds: float = 1e5) -> Probes:
    """A `probe` fixture for use outside pytest (making references, rtpy's own tests):
    each call may take up to `seconds`."""
    plugin = Judge(runner, registry, test_timeout=seconds)
    plugin._deadline = time.monotonic() + seconds
    return Probes(plugin, "")


@pytest.fixture
def probe(request) -> Probes:
    """The graders' fixture (each week's conftest.py imports it): the judge's probes
    when the judge runs the tests; under plain `python -m pytest assignments/weekNN`,
    probes answered by a child process in this repository, for the whole session."""
    config = request.config
    for plugin in config.pluginmanager.get_plugins():
        if isinstance(plugin, Judge):
            return Probes(plugin, request.node.nodeid)
    folder = Path(request.node.path).parent
    if folder.name == "hidden":
        folder = folder.parent
    judges = config.__dict__.setdefault("_rtpy_probe_judges", {})  # one per week's folder
    standalone = judges.get(folder)
    if standalone is None:
        from .graders import local_runner

        probes_file = folder / "probes.py"
        registry = probe_registry([probes_file] if probes_file.is_file() else [])
        standalone = judges[folder] = Judge(local_runner(folder), registry, test_timeout=1e5)
        config.add_cleanup(standalone.runner.stop)
    standalone._deadline = time.monotonic() + standalone.test_timeout
    return Probes(standalone, request.node.nodeid)
