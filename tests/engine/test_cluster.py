"""rtpy.engine.cluster: renders on Dask distributed give the image of `-j 2`, bit for bit:
on a real `dask scheduler` with two `dask worker` processes on 127.0.0.1 (started
here, bounded, stopped by process id), with one of them killed mid-render, on a
`--cluster local`, with a student's plugin shipped to the workers; and the clear
errors of a cluster that cannot render."""

from __future__ import annotations

import json
import os
import re
import signal
import subprocess
import sys
import time
from multiprocessing import resource_tracker
from pathlib import Path

import numpy as np
import pytest

import rtpy
from rtpy.engine.cluster import CLUSTER_TIMEOUT, make_cluster
from rtpy.engine.executor import WorkerError
from rtpy.numpy_backend import renderer as numpy_renderer

from ..cli.test_main import material_registry  # noqa: F401 (a fixture the tests use)
from ..commands import read_until, run_cli
from .test_signals import child_processes, group_processes

distributed = pytest.importorskip("distributed")

STARTUP_SECONDS = 90  # the most a scheduler or a worker may take to start here
SCENE = "week08_three_balls"
RENDER = {"width": 96, "spp": 24, "seed": 3, "backend": "numpy"}  # 96 x 54
SMALL_UNITS = 4096  # paths per numpy unit: 5, 5, 10, 20, 40 and 40 units a pass


def dask_command(*args: str) -> list[str]:
    """`dask ARGS` (the command) with this interpreter's Dask."""
    return [sys.executable, "-m", "dask", *args]


def wait_for(condition, what: str, timeout: float = STARTUP_SECONDS):
    """condition()'s first true value, polled until `timeout` seconds have passed."""
    deadline = time.monotonic() + timeout
    while time.monotonic() < deadline:
        value = condition()
        if value:
            return value
        time.sleep(0.05)  # polling a condition, not waiting out a race
    raise AssertionError(f"{what}: not within {timeout} s")


class DaskProcesses:
    """A `dask scheduler` and `dask worker` processes on 127.0.0.1 in `folder`,
    stopped by process id."""

    def __init__(self, folder: Path) -> None:
        self.folder = folder
        self.file = folder / "scheduler.json"
        self.processes: list[subprocess.Popen] = []
        self.scheduler = self._start(
            "scheduler", "--host", "127.0.0.1", "--port", "0", "--no-dashboard",
            "--scheduler-file", str(self.file),
        )  # fmt: skip
        self.address = wait_for(self._address, "the scheduler's address")
        self.workers = [self.start_worker(), self.start_worker()]

    def _start(self, *args: str) -> subprocess.Popen:
        log = open(self.folder / f"{args[0]}-{len(self.processes)}.log", "w")  # noqa: SIM115
        proc = subprocess.Popen(dask_command(*args), stdout=log, stderr=log, cwd=self.folder)
        log.close()
        self.processes.append(proc)
        return proc

    def _address(self) -> str | None:
        try:
            return json.loads(self.file.read_text())["address"]
        except (OSError, ValueError, KeyError):
            return None

    def start_worker(self) -> subprocess.Popen:
        return self._start(
            "worker", self.address, "--nthreads", "1", "--no-nanny", "--no-dashboard",
            "--host", "127.0.0.1", "--name", f"w{len(self.processes)}",
        )  # fmt: skip

    def stop(self) -> None:
        """Workers first, then the scheduler: a worker whose scheduler is gone first
        spends its timeout trying to reach it before it exits."""
        for proc in reversed(self.processes):
            if proc.poll() is None:
                proc.terminate()
            try:
                proc.wait(timeout=10)
            except subprocess.TimeoutExpired:
                proc.kill()
                proc.wait()


@pytest.fixture(scope="module")
def dask_cluster(tmp_path_factory):
    processes = DaskProcesses(tmp_path_factory.mktemp("dask"))
    try:
        with distributed.Client(processes.address, timeout=STARTUP_SECONDS) as client:
            client.wait_for_workers(2, timeout=STARTUP_SECONDS)
        yield processes
    finally:
        processes.stop()


@pytest.fixture
def small_units(monkeypatch):
    """Units of SMALL_UNITS paths (the plan is made in this process)."""
    monkeypatch.setattr(numpy_renderer, "MAX_RAYS", SMALL_UNITS)


@pytest.fixture(scope="module")
def two_workers_here():
    """RENDER on `-j 2` (worker processes of this machine), in units of SMALL_UNITS."""
    with pytest.MonkeyPatch.context() as m:
        m.setattr(numpy_renderer, "MAX_RAYS", SMALL_UNITS)
        return rtpy.render(rtpy.load_scene(SCENE), workers=2, **RENDER).linear


@pytest.mark.slow
def test_a_scheduler_with_two_workers_gives_the_image_of_two_local_workers(
    dask_cluster, small_units, two_workers_here
):
    image = rtpy.render(rtpy.load_scene(SCENE), cluster=dask_cluster.address, **RENDER)
    assert image.stats["executor"] == "dask" and image.stats["workers"] == 2
    np.testing.assert_array_equal(image.linear, two_workers_here)


@pytest.mark.slow
def test_a_client_of_ones_own_is_used_and_left_open(dask_cluster, small_units, two_workers_here):
    with distributed.Client(dask_cluster.address, timeout=STARTUP_SECONDS) as client:
        image = rtpy.render(rtpy.load_scene(SCENE), cluster=client, **RENDER)
        assert client.status == "running"
    np.testing.assert_array_equal(image.linear, two_workers_here)


@pytest.mark.slow
@pytest.mark.usefixtures("material_registry")
def test_a_plugin_material_travels_to_the_workers(dask_cluster, tmp_path):
    """The workers have not the student's file: its source goes with the render and
    runs there under the name it has here; the image is that of -j 2."""
    plugin = tmp_path / "tint.py"
    plugin.write_text(
        "from rtpy.materials import Lambertian, register_material\n"
        "from rtpy.vec3 import Color\n\n"
        '@register_material("cluster_tint")\n'
        "class Tint(Lambertian):\n"
        "    def __init__(self, level: float = 0.5):\n"
        "        super().__init__(Color(level, 0.25, 0.5 * level))\n"
    )
    scene_file = tmp_path / "scene.toml"
    scene_file.write_text(
        '[render]\nsky = true\n[materials.m]\ntype = "cluster_tint"\nlevel = 0.8\n'
        '[[objects]]\ntype = "sphere"\ncenter = [0, 0, -1]\nradius = 0.5\nmaterial = "m"\n'
    )
    rtpy.load_plugin(plugin)
    scene = rtpy.load_scene(str(scene_file))
    here = rtpy.render(scene, width=48, spp=4, workers=2).linear
    there = rtpy.render(scene, width=48, spp=4, cluster=dask_cluster.address).linear
    np.testing.assert_array_equal(there, here)


@pytest.mark.slow
def test_workers_with_another_rtpy_are_refused(dask_cluster, monkeypatch):
    scene, camera = rtpy.load_scene(SCENE), None
    monkeypatch.setattr("rtpy.engine.cluster.version", lambda: "99.0")  # here, not there
    with pytest.raises(WorkerError, match=r"has rtpy .*; this machine rtpy 99\.0"):
        rtpy.render(scene, camera=camera, width=16, spp=1, cluster=dask_cluster.address)


@pytest.mark.slow
def test_a_worker_killed_mid_render_changes_nothing(dask_cluster, small_units, two_workers_here):
    """SIGKILL to one of the two workers while it renders units (the scheduler says
    so): Dask runs its units again on the other, and the image is the one of -j 2.
    (This test ends the module's first worker: it runs last.)"""
    victim = dask_cluster.workers[0]
    killed = []

    with distributed.Client(dask_cluster.address, timeout=STARTUP_SECONDS) as client:
        victims = [a for a, info in client.scheduler_info()["workers"].items()
                   if info["name"] == "w1"]  # fmt: skip

        def kill_while_it_renders(image) -> None:
            if not killed and client.processing(workers=victims)[victims[0]]:
                victim.send_signal(signal.SIGKILL)
                killed.append(victim.wait(timeout=STARTUP_SECONDS))

        image = rtpy.render(
            rtpy.load_scene(SCENE), cluster=client, preview=kill_while_it_renders,
            preview_seconds=0, **RENDER,
        )  # fmt: skip
    assert killed == [-signal.SIGKILL], "the worker was never seen rendering"
    assert not image.interrupted and image.samples_min == RENDER["spp"]
    np.testing.assert_array_equal(image.linear, two_workers_here)


@pytest.mark.slow
def test_a_local_cluster_gives_the_image_of_two_local_workers(small_units, two_workers_here):
    """... and leaves this process's environment as it was (Dask's nanny sets its
    workers' variables, MALLOC_TRIM_THRESHOLD_ among them, in the process)."""
    environment = dict(os.environ)
    image = rtpy.render(rtpy.load_scene(SCENE), cluster="local", workers=2, **RENDER)
    assert image.stats["executor"] == "dask" and image.stats["workers"] == 2
    np.testing.assert_array_equal(image.linear, two_workers_here)
    assert dict(os.environ) == environment


@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
@pytest.mark.slow
def test_a_local_cluster_leaves_no_process_when_the_render_returns():
    """Not even multiprocessing's resource tracker, which the cluster's processes
    (started by spawn) start, and which would otherwise end only after this one."""
    resource_tracker._resource_tracker._stop()  # as in a new process: not yet started
    before = child_processes(os.getpid())
    rtpy.render(rtpy.load_scene(SCENE), cluster="local", workers=2, **RENDER)
    assert child_processes(os.getpid()) == before


def paths_done(text: str) -> float:
    """The paths the progress bar last showed done (tqdm's 4.10k, 1.2M)."""
    found = re.findall(r"([\d.]+)([kMG]?)/[\d.]+[kMG]? \[", text)
    if not found:
        return 0.0
    number, scale = found[-1]
    return float(number) * {"": 1, "k": 1e3, "M": 1e6, "G": 1e9}[scale]


@pytest.mark.slow
@pytest.mark.skipif(not sys.platform.startswith("linux"), reason="reads /proc")
def test_ctrl_c_on_a_local_cluster_keeps_whole_passes_and_leaves_no_process(tmp_path):
    """A terminal's Ctrl-C goes to every process of the group: the cluster's workers
    ignore it, rtpy stops the render, keeps what is finished (the whole passes as an
    image, and the state; the units may come back in any order, so the first pass
    may still be missing), closes the cluster: exit 130, no traceback, no process."""
    out = tmp_path / "c.png"
    proc = subprocess.Popen(
        [sys.executable, "-m", "rtpy", "render", "cornell", "--width", "64", "--spp",
         "100000", "--backend", "numpy", "-j", "2", "--cluster", "local", "-o", str(out)],
        stderr=subprocess.PIPE, text=True, start_new_session=True,
    )  # fmt: skip
    read_until(proc, lambda text: paths_done(text) >= 4 * 64 * 64)  # 3 passes of paths
    os.killpg(proc.pid, signal.SIGINT)
    _, err = proc.communicate(timeout=120)
    assert proc.returncode == 130 and "Traceback" not in err, err
    assert ("holding" in err) == out.exists() and "--resume continues it" in err, err
    assert (tmp_path / "c.png.resume.npz").exists()
    assert group_processes(proc.pid) == []


def test_a_cluster_is_local_an_address_or_a_client():
    with pytest.raises(ValueError, match=r"cluster: expected \"local\" or a scheduler's address"):
        make_cluster("somewhere")
    with pytest.raises(TypeError, match="cluster: expected"):
        make_cluster(8786)
    assert make_cluster("tcp://127.0.0.1:8786", 3).workers == 3


MALFORMED = {
    "tcp://127.0.0.1": "the port is missing",
    "tcp://:8786": "the host is empty",
    "tcp://127.0.0.1:port": "the port 'port' is not a number",
    "udp://127.0.0.1:8786": "the scheme is udp://, not tcp://",
    "tcp://127.0.0.1:8786:8787": "it has two ports",
    "tcp://127.0.0.1:0": "the port 0 is not from 1 to 65535",
    "tcp://[::1": "an IPv6 host is written in brackets",
    "tcp://lab 00:8786": "'lab 00' is not a host name or address",
    "127.0.0.1:8786": "no tcp:// before the host",
}


@pytest.mark.parametrize("address", MALFORMED)
def test_a_malformed_address_is_a_value_error_naming_cluster_before_dask_sees_it(
    address, monkeypatch
):
    def no_client(*args, **kwargs):
        raise AssertionError("Dask was asked")

    monkeypatch.setattr(distributed, "Client", no_client)
    with pytest.raises(ValueError) as caught:
        rtpy.render(rtpy.load_scene(SCENE), width=8, spp=1, cluster=address)
    message = str(caught.value)
    assert message.startswith("cluster: expected") and MALFORMED[address] in message
    assert repr(address) in message and "\n" not in message


def test_addresses_dask_takes_are_kept():
    for address in ("tcp://lab00:8786", "tcp://10.0.0.2:1", "tcp://[::1]:65535"):
        assert make_cluster(address).cluster == address
    assert make_cluster("tcp://127.0.0.1:08786").cluster == "tcp://127.0.0.1:8786"


@pytest.mark.parametrize("timeout, error", [(0, ValueError), (-1.0, ValueError),
                                            (float("nan"), ValueError), ("5", TypeError),
                                            (True, TypeError)])  # fmt: skip
def test_the_connect_timeout_is_checked(timeout, error):
    with pytest.raises(error, match="^cluster_timeout: expected"):
        make_cluster("tcp://127.0.0.1:8786", 1, timeout)
    assert make_cluster("tcp://127.0.0.1:8786").timeout == CLUSTER_TIMEOUT <= 10


def closed_port() -> int:
    """A port of 127.0.0.1 where nothing listens (bound a moment, then released)."""
    import socket

    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        return s.getsockname()[1]


@pytest.mark.slow
def test_a_scheduler_that_is_not_there_is_one_error_within_the_timeout():
    address = f"tcp://127.0.0.1:{closed_port()}"
    started = time.monotonic()
    with pytest.raises(
        WorkerError, match=f"cannot reach the Dask scheduler at {address} within 1 s"
    ):
        rtpy.render(rtpy.load_scene(SCENE), width=8, spp=1, cluster=address, cluster_timeout=1)
    assert time.monotonic() - started < 5  # Dask's own default is 30 s and more


@pytest.mark.slow
def test_the_default_timeout_answers_a_closed_port_within_10_seconds(tmp_path):
    address = f"tcp://127.0.0.1:{closed_port()}"
    started = time.monotonic()
    result = run_cli("render", SCENE, "--width", "8", "--spp", "1", "-q", "-o",
                     str(tmp_path / "x.png"), "--cluster", address, timeout=60)  # fmt: skip
    assert time.monotonic() - started < 10, result.stderr
    assert result.returncode == 1 and len(result.stderr.splitlines()) == 1, result.stderr
    assert "cannot reach the Dask scheduler" in result.stderr and list(tmp_path.iterdir()) == []
