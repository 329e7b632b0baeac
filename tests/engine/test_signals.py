"""SIGINT and SIGTERM at any moment: the handlers of rtpy.engine.signals in this process, and
real renders (`python -m rtpy render`) signalled at random moments, from the
interpreter's start-up to the end of the write.

A random run prints its seed, delay and what it saw in the assertion message;
RTPY_SIGNAL_SEED=SEED reruns that one run (the loop's other runs are skipped).
POSIX only: Windows has no SIGTERM to catch, and os.kill there ends a process
without a handler running (rtpy/engine/signals.py).
"""

from __future__ import annotations

import os
import random
import re
import signal
import subprocess
import sys
import threading
import time
from collections.abc import Iterator
from dataclasses import dataclass
from functools import cache
from pathlib import Path

import numpy as np
import pytest

import rtpy
from rtpy.engine import files, signals
from rtpy.engine.backend import make_backend
from rtpy.engine.pixel_sums import PixelSums

from ..commands import read_until, rtpy_command

pytestmark = pytest.mark.skipif(sys.platform == "win32", reason="POSIX signals")

SCENE = "week08_three_balls"
WIDTH = 32  # 32x18
SPP = {"scalar": 8, "numpy": 128}  # passes of 1, 1, 2, 4; and 1, 1, 2, ..., 64
RTPY_FILES = str(Path(rtpy.__file__).parent) + os.sep


FRAME = re.compile(r'File "(.*)", line (\d+), in (\S+)')
INIT = Path(rtpy.__file__)
DEFER_LINE = next(  # the line of rtpy/__init__.py that installs the handlers
    n for n, line in enumerate(INIT.read_text().splitlines(), 1) if "signals.defer()" in line
)


# The modules imported before rtpy/__init__.py calls signals.defer(): the engine
# package, rtpy.engine.signals and what it imports.
BEFORE_DEFER = [INIT] + [
    INIT.parent / "engine" / f for f in ("__init__.py", "signals.py", "exit_status.py")
]


def before_handlers(err: str) -> bool:
    """The traceback on stderr is from before rtpy installs its handlers: no frame in
    rtpy but the module-level code of rtpy/__init__.py up to signals.defer() and of
    the modules imported before it (Python's own KeyboardInterrupt, while the
    interpreter starts)."""
    for path, line, function in FRAME.findall(err):
        if not path.startswith(RTPY_FILES):
            continue
        if function != "<module>" or path not in map(str, BEFORE_DEFER):
            return False
        if path == str(INIT) and int(line) > DEFER_LINE:
            return False
    return True


def test_a_traceback_is_told_from_before_the_handlers_by_its_frames():
    """The interpreter's KeyboardInterrupt while `import rtpy` reaches signals.defer()
    is told apart from one later (the random-moment runs accept only the first)."""
    assert all(path.is_file() for path in BEFORE_DEFER)

    def frame(path, line):
        return f'  File "{path}", line {line}, in <module>\n'

    signals_py, exit_status_py = BEFORE_DEFER[2:]
    early = frame(INIT, DEFER_LINE - 1) + frame(signals_py, 1) + frame(exit_status_py, 1)
    assert before_handlers("Traceback (most recent call last):\n" + early)
    late = frame(INIT, DEFER_LINE + 1) + frame(INIT.parent / "camera.py", 1)
    assert not before_handlers("Traceback (most recent call last):\n" + late)


# --- the handlers, in this process ------------------------------------------------


@pytest.fixture(autouse=True)
def fresh_signals(monkeypatch):
    """No signal received before the test; the handlers as they were after it."""
    monkeypatch.setattr(signals, "_received", [])
    before = {s: signal.getsignal(s) for s in signals.STOP_SIGNALS}
    yield
    for s, handler in before.items():
        signal.signal(s, handler)


def test_first_signal_raises_keyboard_interrupt_and_handlers_are_restored():
    before = {s: signal.getsignal(s) for s in signals.STOP_SIGNALS}
    with pytest.raises(KeyboardInterrupt):
        with signals.stop_on_signals():
            signal.raise_signal(signal.SIGTERM)
    assert signals.received() == signal.SIGTERM and signals.exit_status() == 143
    assert {s: signal.getsignal(s) for s in signals.STOP_SIGNALS} == before
    with signals.stop_on_signals():  # a new command forgets the last one's signal
        assert signals.received() is None and signals.exit_status() == 130


def test_a_signal_while_a_finished_image_is_written_lets_the_write_finish():
    with signals.stop_on_signals():
        with signals.finishing():
            signal.raise_signal(signal.SIGTERM)  # recorded: no KeyboardInterrupt here
            for _ in range(1000):  # bytecodes where a handler would run
                pass
        assert signals.received() == signal.SIGTERM


def test_a_signal_while_starting_is_recorded_then_stops_the_command():
    signals.defer()
    signal.raise_signal(signal.SIGINT)  # recorded: no KeyboardInterrupt here
    assert signals.received() == signal.SIGINT
    with pytest.raises(KeyboardInterrupt), signals.stop_on_signals():
        pytest.fail("the command ran after a signal while starting")


def test_signals_held_while_a_pool_starts_reach_the_handler_after():
    """Inside held() a signal is neither lost nor handled (fork would lose the
    KeyboardInterrupt of a handler run in its hooks); it is handled on leaving. The
    signal comes from another thread and is sent to the main thread, which blocks it
    there: it stays pending until held() ends. (Sent to the process, it could go to
    any thread that does not block it, such as a progress bar's monitor left by an
    earlier test, and be handled whenever that thread runs: a race, not a test.)"""
    go = threading.Event()
    main = threading.main_thread().ident
    sender = threading.Thread(target=lambda: go.wait() and signal.pthread_kill(main, signal.SIGINT))
    sender.start()
    reached = False
    with pytest.raises(KeyboardInterrupt):  # Python's own handler
        with signals.held():
            go.set()
            sender.join()
            for _ in range(1000):  # bytecodes where a handler would run
                pass
            reached = True
    assert reached


def test_an_error_an_interrupt_caused_counts_as_the_interrupt():
    """An import cut short by Ctrl-C can end in another exception raised from it."""
    try:
        try:
            raise KeyboardInterrupt
        except KeyboardInterrupt as ki:
            raise RuntimeError("Error calling __set_name__") from ki
    except RuntimeError as err:
        assert signals.caused_by_interrupt(err)
    assert not signals.caused_by_interrupt(RuntimeError("a real error"))


def test_stopping_removes_the_temporary_files_of_interrupted_writes(tmp_path, capsys):
    """A Ctrl-C between the creation of a temporary file and the try that removes
    it leaves the file listed; the command's end removes it."""
    tmp = files._new_temporary_file(tmp_path / "out.png")
    assert tmp.exists()
    assert signals.stopped("interrupted: nothing was written") in (130, 143)
    assert not tmp.exists() and "rtpy: interrupted: nothing was written" in capsys.readouterr().err


@pytest.mark.parametrize(
    "argv,orig_argv,expected",
    [
        (["-m"], ["python", "-X", "dev", "-m", "rtpy", "render"], True),
        (["-m"], ["python", "-m", "pytest"], False),
        (["/venv/bin/rtpy", "render"], ["/venv/bin/python", "/venv/bin/rtpy"], True),
        (["script.py"], ["python", "script.py"], False),
        ([], ["python"], False),
    ],
)
def test_only_the_command_line_installs_handlers_while_rtpy_is_imported(
    monkeypatch, argv, orig_argv, expected
):
    monkeypatch.setattr(sys, "argv", argv)
    monkeypatch.setattr(sys, "orig_argv", orig_argv)
    assert signals.starting_the_command_line() is expected


# --- real renders -------------------------------------------------------------------


@dataclass
class Run:
    """One render signalled after `delay` seconds (and again after `again` more
    seconds, unless None), with an existing output or none."""

    backend: str
    workers: int
    signum: int
    delay: float
    again: float | None
    existing: bool
    group: bool = False  # to the process group (as a terminal's Ctrl-C), not the parent
    spp: int = 0  # 0: SPP[backend], whose images are checked value by value

    @property
    def samples(self) -> int:
        return self.spp or SPP[self.backend]

    def describe(self, seed: int | None) -> str:
        name = signal.Signals(self.signum).name
        second = f", again after {self.again:.3f} s" if self.again is not None else ""
        return (
            f"RTPY_SIGNAL_SEED={seed}: {self.backend} -j {self.workers}, {name} to the "
            f"{'group' if self.group else 'parent'} after {self.delay:.3f} s{second}, "
            f"existing output: {self.existing}"
        )


OLD = b"an existing output\n"


def start(run: Run, folder: Path) -> tuple[subprocess.Popen, list[Path]]:
    outputs = [folder / "out.png", folder / "out.npy"]
    if run.existing:
        for path in outputs:
            path.write_bytes(OLD)
    args = ["render", SCENE, "--width", str(WIDTH), "--spp", str(run.samples)]
    args += ["-j", str(run.workers), "--backend", run.backend, "-o", str(outputs[0])]
    args += ["--linear", str(outputs[1])]
    proc = subprocess.Popen(
        rtpy_command(*args, *(["-q"] if run.delay >= 0 else [])),
        stderr=subprocess.PIPE,
        text=True,
        start_new_session=True,  # a process group of its own: its workers are in it
        preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL),  # as in a shell
    )
    return proc, outputs


def signal_and_wait(proc: subprocess.Popen, run: Run) -> str:
    """Send the signals at their moments; what the process said on stderr."""
    time.sleep(run.delay)
    send(proc, run)
    if run.again is not None:
        time.sleep(run.again)
        send(proc, run)
    return proc.communicate(timeout=60)[1]


def send(proc: subprocess.Popen, run: Run) -> None:
    if not run.group:
        proc.send_signal(run.signum)
        return
    try:
        os.killpg(proc.pid, run.signum)
    except ProcessLookupError:  # the group has ended
        pass


def _processes() -> Iterator[tuple[int, int, str]]:
    """(parent, group, "pid (name) command line") of each process still running
    (Linux /proc; zombies left out)."""
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            text = stat.read_text()
            command = (stat.parent / "cmdline").read_bytes().replace(b"\0", b" ")
        except OSError:  # it ended meanwhile
            continue
        state, parent, group = text.rsplit(")", 1)[1].split()[:3]  # after "pid (name)"
        if state != "Z":
            name = text.split(")", 1)[0] + ")"
            yield int(parent), int(group), f"{name} {command.decode(errors='replace')[:200]}"


def group_processes(pgid: int) -> list[str]:
    """The processes of group pgid still running."""
    return [process for _, group, process in _processes() if group == pgid]


def child_processes(pid: int) -> list[str]:
    """The children of process pid still running."""
    return [process for parent, _, process in _processes() if parent == pid]


@cache
def whole_passes(backend_name: str) -> dict[int, np.ndarray]:
    """samples -> the image of the first passes holding them, at SPP[backend_name],
    rendered here: what the command writes, bit for bit, whatever its workers."""
    scene = rtpy.load_scene(SCENE)
    camera = scene.camera.with_width(WIDTH)
    spp = SPP[backend_name]
    backend = make_backend(backend_name, scene, camera, scene.settings.with_overrides(spp=spp))
    plan = backend.plan(camera.width, camera.height, spp)
    render_one = backend.start()
    results = [(unit, render_one(unit)) for unit in plan.units()]
    images = {}
    for passes in range(1, len(plan.passes) + 1):
        sums = PixelSums(plan)
        for unit, unit_sums in results:
            if unit.batch < passes:
                sums.add(unit, unit_sums)
        images[plan.samples_after(passes)] = sums.mean()
    return images


def samples_of(run: Run, linear: np.ndarray) -> int | None:
    """The samples per pixel of the whole passes the image is, bit for bit, else
    AssertionError; None when the run's spp is not SPP[backend] (not rendered here)."""
    if run.samples != SPP[run.backend]:
        return None
    for samples, image in whole_passes(run.backend).items():
        if np.array_equal(linear, image):
            return samples
    raise AssertionError("the image is not that of whole passes")


def check(run: Run, proc: subprocess.Popen, err: str, outputs: list[Path], folder: Path):
    status = proc.returncode
    # Before rtpy's handlers are installed, and while the interpreter exits after
    # rtpy's last word, a signal has its default effect: SIGTERM ends the process,
    # SIGINT too, or raises KeyboardInterrupt in the interpreter's own start-up
    # (before any rtpy code runs: docs/students.md).
    in_interpreter = "Traceback" in err and before_handlers(err) and status in (1, -2)
    said = "rtpy: wrote" in err or "rtpy: interrupted" in err
    by_default = status == -run.signum and (said or "rtpy" not in err) or in_interpreter
    assert status in (0, signals.EXIT_STATUS[run.signum]) or by_default, f"exit status {status}"
    assert said or by_default, "no message"
    assert "Traceback" not in err or in_interpreter
    assert not [p.name for p in folder.iterdir() if p.suffix == ".tmp"], "temporary files"
    assert group_processes(proc.pid) == [], "processes left running"
    written = [p for p in outputs if p.exists() and p.read_bytes() != OLD]
    held = re.search(r"holding (\d+) of (\d+) samples per pixel", err)
    if "rtpy: wrote" in err or "interrupted while writing" in err:  # a finished image
        assert written == outputs
        assert samples_of(run, np.load(outputs[1])) in (None, run.samples)
    elif held is not None:
        assert written == outputs and 1 <= int(held[1]) < run.samples
        assert samples_of(run, np.load(outputs[1])) in (None, int(held[1]))
    elif "stopped at once" in err:  # the outputs written whole before it, or untouched
        if outputs[1] in written:
            samples_of(run, np.load(outputs[1]))  # whole passes
    else:
        assert written == [], "an output changed though the message says nothing was written"


CONFIGS = [("scalar", 1), ("scalar", 2), ("numpy", 1), ("numpy", 2)]
RUNS_PER_CONFIG = 4
LOOP_SEED = 20261201


def random_run(seed: int) -> Run:
    """The run of `seed`: its configuration, signal, moments and existing output."""
    rng = random.Random(seed)
    backend, workers = CONFIGS[seed % len(CONFIGS)]
    again = rng.uniform(0.0, 0.3) if rng.random() < 0.25 else None
    return Run(
        backend,
        workers,
        rng.choice(signals.STOP_SIGNALS),
        delay=rng.uniform(0.0, 1.2),  # start-up (about 0.4 s) to past the end of most runs
        again=again,
        existing=rng.random() < 0.5,
        group=rng.random() < 0.5,
    )


def replay_seed() -> int | None:
    text = os.environ.get("RTPY_SIGNAL_SEED")
    return int(text) if text else None


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
@pytest.mark.parametrize("index", range(len(CONFIGS) * RUNS_PER_CONFIG))
def test_a_signal_at_a_random_moment(tmp_path, index):
    """SIGINT or SIGTERM (sometimes twice) at a random moment of a small render, with
    and without an existing output: the right exit status, no traceback, no
    temporary file, no process left, and the outputs untouched or written whole
    holding whole passes, as the message says."""
    seed = LOOP_SEED + index
    if replay_seed() is not None:
        if index:
            pytest.skip("replaying RTPY_SIGNAL_SEED in the first run")
        seed = replay_seed()
    run = random_run(seed)
    proc, outputs = start(run, tmp_path)
    err = signal_and_wait(proc, run)
    try:
        check(run, proc, err, outputs, tmp_path)
    except AssertionError as e:
        raise AssertionError(f"{run.describe(seed)}: {e}\n{err}") from None


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
@pytest.mark.slow
def test_sigterm_after_a_pass_writes_it_and_exits_143(tmp_path):
    """SIGTERM once the progress bar shows the first passes done (scalar, 2 workers):
    exit 143, the image of the finished passes. The render is long (seconds) so that
    the bar, refreshed every 0.1 s, shows it between 25% and 99% however fast the
    machine."""
    run = Run("scalar", 2, signal.SIGTERM, delay=-1.0, again=None, existing=True, spp=1024)
    proc, outputs = start(run, tmp_path)  # delay < 0: with the progress bar
    seen = read_until(proc, lambda text: re.search(r"(2[5-9]|[3-9]\d)%\|", text) is not None)
    proc.send_signal(signal.SIGTERM)
    err = seen + proc.communicate(timeout=60)[1]
    assert proc.returncode == 143, err
    check(run, proc, err, outputs, tmp_path)
    assert "holding" in err


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
@pytest.mark.parametrize(
    "backend, workers, signum",
    [("numpy", 2, signal.SIGINT), ("scalar", 2, signal.SIGINT), ("numpy", 2, signal.SIGTERM)],
)
def test_a_signal_once_the_bar_shows_100_percent_writes_the_finished_image(
    tmp_path, backend, workers, signum
):
    """The signal sent the moment the progress bar shows every path done (the last
    pass is in; the workers are being ended): the finished image is written, the
    exit status is the signal's, promptly, with no process left."""
    run = Run(backend, workers, signum, delay=-1.0, again=None, existing=True)
    proc, outputs = start(run, tmp_path)  # delay < 0: with the progress bar
    seen = read_until(proc, lambda text: "100%|" in text)
    proc.send_signal(signum)
    err = seen + proc.communicate(timeout=30)[1]  # a hang fails here, after 30 s
    assert proc.returncode == signals.EXIT_STATUS[signum], err
    check(run, proc, err, outputs, tmp_path)
    assert "complete" in err and samples_of(run, np.load(outputs[1])) == run.samples, err
