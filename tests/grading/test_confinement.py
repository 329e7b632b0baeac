"""The sandbox's box, kept from the judge's side (rtpy.grading.confinement): no socket
but a local one behind the filter; every process of the sandbox's user ended by the
judge even when they stop whatever they can; every file it left in the shared
temporary folders removed, and nothing else."""

from __future__ import annotations

import os
import socket
import subprocess
import sys
import time
import uuid
from pathlib import Path

import pytest

from rtpy.grading.confinement import (
    SocketFilter,
    kill_user,
    network_closed,
    remove_user_files,
    remove_user_ipc,
    user_ipc,
    user_processes,
)

LINUX = sys.platform == "linux"
ROOT_USER = LINUX and os.geteuid() == 0
# a Python every user may run (this machine's own may live under /root)
SANDBOX_PYTHON = os.environ.get("RTPY_SANDBOX_PYTHON", "/opt/rtpy-sandbox-python/bin/python")

CONNECT = """import socket, sys
s = socket.socket(socket.AF_INET, socket.SOCK_STREAM)
s.settimeout(5)
s.connect(("127.0.0.1", int(sys.argv[1])))
s.sendall(b"the hidden inputs")
"""
LOCAL = """import socket
a, b = socket.socketpair()
a.sendall(b"ok")
assert b.recv(2) == b"ok"
socket.socket(socket.AF_UNIX, socket.SOCK_STREAM).close()
"""


def connect(port: int, preexec=None) -> subprocess.CompletedProcess:
    return subprocess.run(
        [sys.executable, "-I", "-c", CONNECT, str(port)], preexec_fn=preexec,
        capture_output=True, text=True, timeout=60,
    )  # fmt: skip


@pytest.mark.skipif(not LINUX, reason="the socket filter is Linux's seccomp")
def test_the_filter_refuses_the_network_and_keeps_local_sockets():
    socket_filter, why = network_closed(sys.executable)
    assert socket_filter is not None, why
    with socket.create_server(("127.0.0.1", 0)) as listener:
        listener.settimeout(0.5)
        port = listener.getsockname()[1]
        assert connect(port).returncode == 0  # the trial is fair: it can connect
        listener.accept()[0].close()
        refused = connect(port, socket_filter.install)
        assert refused.returncode != 0 and "PermissionError" in refused.stderr, refused.stderr
        with pytest.raises(TimeoutError):
            listener.accept()  # nothing came
    local = subprocess.run(
        [sys.executable, "-I", "-c", LOCAL], preexec_fn=socket_filter.install,
        capture_output=True, text=True, timeout=60,
    )  # fmt: skip
    assert local.returncode == 0, local.stderr


def test_where_there_is_no_filter_it_says_why(monkeypatch):
    monkeypatch.setattr("platform.machine", lambda: "pdp11")
    found = SocketFilter()
    assert not found.ready and "pdp11" in found.reason
    found.install()  # nothing to install: nothing done


# --- as root, with a user of the test's own -------------------------------------------------
@pytest.fixture
def user():
    """A system user made for this test (root only), removed afterwards."""
    if not ROOT_USER or not os.path.isfile(SANDBOX_PYTHON):
        pytest.skip("needs root on Linux (a user of the test's own) and RTPY_SANDBOX_PYTHON")
    import pwd

    name = f"rtpy-test-{uuid.uuid4().hex[:8]}"
    made = subprocess.run(
        ["useradd", "--system", "--no-create-home", "--shell", "/usr/sbin/nologin", name],
        capture_output=True,
    )
    if made.returncode != 0:
        pytest.skip("useradd failed")
    entry = pwd.getpwnam(name)
    yield entry.pw_uid, entry.pw_gid
    kill_user(entry.pw_uid)
    remove_user_files(entry.pw_uid, entry.pw_gid)
    remove_user_ipc(entry.pw_uid)
    subprocess.run(["userdel", name], capture_output=True)


# Processes that hide (undumpable: /proc/PID owned by root), leave the session, and keep
# stopping every process id just above their own (where a helper of the judge's would
# start): a judge that needs a process of this user to kill them waits forever.
STOPPER = """import ctypes, os, signal, sys, time
ctypes.CDLL(None).prctl(4, 0, 0, 0, 0)  # PR_SET_DUMPABLE 0
for _ in range(3):
    if os.fork() == 0:
        os.setsid()
        break
open(os.path.join(sys.argv[1], "started-%d" % os.getpid()), "w").close()
while len(os.listdir(sys.argv[1])) < 4:  # all four started before any stops another
    time.sleep(0.01)
end = time.monotonic() + 120
while time.monotonic() < end:
    me = os.getpid()
    for pid in range(me - 50, me + 400):
        if pid != me:
            try:
                os.kill(pid, signal.SIGSTOP)
            except OSError:
                pass
"""


@pytest.fixture
def open_tmp():
    """A folder the test's user can reach (pytest's own are closed to other users)."""
    import shutil
    import tempfile

    folder = Path(tempfile.mkdtemp(prefix="rtpy-confinement-", dir="/tmp"))
    os.chmod(folder, 0o755)
    yield folder
    shutil.rmtree(folder, ignore_errors=True)


def as_user(ids, *args, **options) -> subprocess.Popen:
    return subprocess.Popen(
        [SANDBOX_PYTHON, "-I", "-S", *args], user=ids[0], group=ids[1], extra_groups=[],
        cwd="/", **options,
    )  # fmt: skip


def test_every_process_of_the_user_is_killed_by_the_judge_itself(user, open_tmp, monkeypatch):
    """Processes that hide, leave the session and stop every process they may are all
    killed, and by this process: no helper is forked (it could become one they stop)."""
    marks = open_tmp / "marks"
    marks.mkdir()
    os.chmod(marks, 0o777)
    first = as_user(user, "-c", STOPPER, str(marks))
    deadline = time.monotonic() + 30
    while len(list(marks.iterdir())) < 4 and time.monotonic() < deadline:
        time.sleep(0.05)
    assert len(list(marks.iterdir())) == 4, "the stoppers did not start"
    assert len(user_processes(user[0])) >= 4  # undumpable ones included
    start = time.monotonic()

    def no_helper(*args):
        raise AssertionError("kill_user started a process to do its work")

    with monkeypatch.context() as patched:
        for name in ("fork", "setuid", "setresuid", "posix_spawn"):
            patched.setattr(os, name, no_helper, raising=False)
        patched.setattr(subprocess, "Popen", no_helper)
        assert kill_user(user[0], seconds=10.0)
    assert time.monotonic() - start < 10.0
    first.wait(timeout=10)
    assert user_processes(user[0]) == []


def test_the_users_files_are_removed_and_no_other(user, open_tmp):
    tmp_path = open_tmp
    places = [tmp_path / name for name in ("tmp", "shm", "closed")]
    for place in places:
        place.mkdir()
        os.chmod(place, 0o1777)
    theirs = tmp_path / "root-file"
    theirs.write_text("root's")
    (places[0] / "root-owned").write_text("stays")
    writer = f"""import os
base = {str(tmp_path)!r}
open(os.path.join(base, "tmp", "left.txt"), "w").write("x")
os.makedirs(os.path.join(base, "tmp", "deep", "deeper"))
open(os.path.join(base, "tmp", "deep", "deeper", "f"), "w").write("x")
os.chmod(os.path.join(base, "tmp", "deep"), 0o500)
os.symlink(os.path.join(base, "root-file"), os.path.join(base, "shm", "link"))
os.mkfifo(os.path.join(base, "shm", "fifo"))
os.mkdir(os.path.join(base, "closed", "open"))
os.chmod(os.path.join(base, "closed", "open"), 0o777)
"""
    assert as_user(user, "-c", writer).wait(timeout=60) == 0
    open_dir = places[2] / "open"  # the user's, in a folder then closed to it: still found
    os.chmod(places[2], 0o755)
    removed = remove_user_files(user[0], user[1], places=[str(p) for p in places])
    assert sorted(Path(p).name for p in removed) == ["deep", "fifo", "left.txt", "link", "open"]
    assert not open_dir.exists()
    assert sorted(p.name for p in places[0].iterdir()) == ["root-owned"]
    assert list(places[1].iterdir()) == []
    assert theirs.read_text() == "root's"  # the link was removed, not what it names


IPC = """import ctypes
libc = ctypes.CDLL(None, use_errno=True)
assert libc.shmget(0, 4096, 0o1600) >= 0  # IPC_PRIVATE, IPC_CREAT | 0600
assert libc.msgget(0, 0o1600) >= 0
assert libc.semget(0, 1, 0o1600) >= 0
"""


def test_the_users_ipc_objects_are_removed(user):
    """Shared memory, a message queue and a semaphore set made by the user outlive its
    processes until they are removed; root's are left."""
    assert as_user(user, "-c", IPC).wait(timeout=60) == 0
    assert sorted(kind for kind, _ in user_ipc(user[0])) == ["msg", "sem", "shm"]
    roots = user_ipc(0)
    assert sorted(kind for kind, _ in remove_user_ipc(user[0])) == ["msg", "sem", "shm"]
    assert user_ipc(user[0]) == []
    assert user_ipc(0) == roots


def test_root_is_never_the_target():
    with pytest.raises(ValueError, match="uid"):
        kill_user(0)
    with pytest.raises(ValueError, match="uid"):
        remove_user_files(0)
    with pytest.raises(ValueError, match="uid"):
        remove_user_ipc(0)
