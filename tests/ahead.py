"""Heavy checks computed ahead, at the lowest priority, while the suite runs.

A module's heavy checks (tests/cores.py: module_outcomes, selected_checks) are pure
functions of their parameters. Many test files run one subprocess or one thread at a
time, which leaves a core idle for much of a full run. Once the tests are collected,
one background process (`python -m tests.ahead FOLDER`, niced to 19 where the system
has nice, so the tests in front keep the processor) works through the checks the
session will ask for, in the order the tests run, and leaves each outcome in FOLDER.
A module's fixture takes the outcomes that are there and computes the rest itself
on every core, as without this; the process is stopped meanwhile (by its process id)
and started again for the later modules. Stopped at the end of the session; it also
stops on its own when the tests' process is gone.

The outcome is the same, computed here or there: the checks draw from their own seeds.
A short run (a few test files) does not start it: it would not get ahead.
"""

from __future__ import annotations

import importlib
import os
import pickle
import subprocess
import sys
import tempfile
from pathlib import Path
from typing import Any

ROOT = Path(__file__).resolve().parent.parent
MIN_ITEMS = 500  # tests in the session below which nothing is computed ahead


def key(module: str, test: str, params: dict) -> tuple[str, str, str]:
    """What names one run of a check across processes (tests sharing a check function
    and parameters share the run: cores.selected_checks)."""
    from .cores import CHECKS

    return module, CHECKS[module][test].__qualname__, repr(sorted(params.items()))


class Ahead:
    """The background process and the folder of its outcomes."""

    def __init__(self, work: list[tuple[tuple, str, str, dict]]) -> None:
        self.folder = Path(tempfile.mkdtemp(prefix="rtpy-tests-ahead-"))
        self.index = {k: i for i, (k, *_) in enumerate(work)}
        self.work = work
        self.done: set[int] = set()  # outcomes read
        self.taken: set[int] = set()  # checks a fixture asked for
        self.process: subprocess.Popen | None = None
        self._start([i for i in range(len(work))])

    def _start(self, indices: list[int]) -> None:
        if not indices:
            return
        items = [(i, *self.work[i][1:]) for i in indices]
        (self.folder / "work.pkl").write_bytes(pickle.dumps(items))
        self.process = subprocess.Popen(
            [sys.executable, "-m", "tests.ahead", str(self.folder), str(os.getpid())],
            cwd=ROOT,
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )

    def stop(self) -> None:
        if self.process is not None and self.process.poll() is None:
            self.process.kill()
        if self.process is not None:
            self.process.wait()
        self.process = None

    def _read(self, i: int) -> tuple[bool, Any]:
        path = self.folder / f"{i}.pkl"
        if (self.folder / f"{i}.err").exists():
            self.done.add(i)  # it failed or raised: the fixture computes it, and reports it
            return False, None
        if not path.exists():
            return False, None
        self.done.add(i)
        return True, pickle.loads(path.read_bytes())

    def take(self, keys: list[tuple]) -> dict[tuple, Any]:
        """The outcomes of `keys` computed so far. If some are missing, the process is
        stopped (the caller computes them now) and started again for the checks of
        later modules."""
        wanted = [self.index[k] for k in keys if k in self.index]
        found = {}
        for i in wanted:
            ok, value = self._read(i)
            if ok:
                found[self.work[i][0]] = value
        if len(found) < len(keys) and self.process is not None:
            self.stop()
            for i in wanted:
                ok, value = self._read(i)
                if ok:
                    found[self.work[i][0]] = value
        self.taken.update(wanted)
        if self.process is None:
            left = [i for i in range(len(self.work)) if i not in self.done | self.taken]
            self._start(left)
        return found

    def close(self) -> None:
        self.stop()
        for path in self.folder.iterdir():
            path.unlink()
        self.folder.rmdir()


_ahead: Ahead | None = None


def start(session) -> None:
    """For pytest_collection_finish: the checks of the session's tests, in their order."""
    from .cores import CHECKS, params_of

    global _ahead
    if len(session.items) < MIN_ITEMS:
        return
    work, seen = [], set()
    for item in session.items:
        module = item.module.__name__
        if item.originalname not in CHECKS.get(module, {}):
            continue
        params = params_of(item)
        k = key(module, item.originalname, params)
        if k in seen:
            continue
        try:
            pickle.dumps(params)
        except Exception:  # computed by the module's fixture
            continue
        seen.add(k)
        work.append((k, module, item.originalname, params))
    if work:
        _ahead = Ahead(work)


def take(keys: list[tuple]) -> dict[tuple, Any]:
    return _ahead.take(keys) if _ahead is not None else {}


def finish() -> None:
    """For pytest_sessionfinish."""
    global _ahead
    if _ahead is not None:
        _ahead.close()
        _ahead = None


def serve(folder: Path, parent: int) -> None:
    """The background process: each check of work.pkl in turn, its outcome pickled to
    INDEX.pkl, written whole (a rename); INDEX.err for a check that failed or raised."""
    from .cores import CHECKS, run_check

    if hasattr(os, "nice"):
        os.nice(19)
    for i, module, test, params in pickle.loads((folder / "work.pkl").read_bytes()):
        if os.getppid() != parent:
            return  # the tests' process is gone
        importlib.import_module(module)
        try:
            outcome = run_check((CHECKS[module][test], params))
            if isinstance(outcome, AssertionError):
                raise outcome
            result = pickle.dumps(outcome)
        except Exception:
            # A failure, or an error: the fixture computes it again under pytest, whose
            # assertion rewriting explains it, and reports it.
            (folder / f"{i}.err").touch()
            continue
        partial = folder / f"{i}.tmp"
        partial.write_bytes(result)
        partial.rename(folder / f"{i}.pkl")


if __name__ == "__main__":
    serve(Path(sys.argv[1]), int(sys.argv[2]))
