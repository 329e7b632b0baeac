"""What keeps the sandbox's user in its box, done from the judge's side (Linux).

- `SocketFilter`: a seccomp filter, installed in the child before Python starts, that
  refuses every socket but a local (AF_UNIX) one, and io_uring (which could open
  sockets past the filter): the student's code cannot reach the network, loopback
  included. It needs no privilege (only no_new_privs); where it cannot be installed
  (another OS or architecture, a kernel without seccomp) `network_closed` says why, and
  the instructor's log says so once.
- `kill_user`: every process of the sandbox's user is sent SIGKILL by the judge itself
  (root), each through a pidfd after checking its user, so that no helper the
  submission could stop or signal takes part, and a process id that was reused meanwhile
  is never hit.
- `remove_user_files`: after its processes are gone, every file the user owns in the
  folders any user may write (TMP_PLACES) is removed, so nothing a run wrote survives
  for a later run's user, which may get the same uid; `remove_user_ipc` does the same
  for its System V shared memory, message queues and semaphores.
"""

from __future__ import annotations

import ctypes
import functools
import os
import platform
import shutil
import signal
import stat
import struct
import subprocess
import sys
import time
from pathlib import Path

TMP_PLACES = ("/tmp", "/var/tmp", "/dev/shm", "/run/lock", "/var/lock", "/dev/mqueue")
KILL_SECONDS = 10.0  # to end every process of the user (16 at most: RLIMIT_NPROC)

# --- the socket filter ------------------------------------------------------------------
# (audit architecture, socket's number, io_uring_setup's number, x32's syscall bit)
ARCHITECTURES = {
    "x86_64": (0xC000003E, 41, 425, 0x40000000),
    "aarch64": (0xC00000B7, 198, 425, None),
}
AF_UNIX = 1
EACCES = 13
PR_SET_NO_NEW_PRIVS, PR_SET_SECCOMP, SECCOMP_MODE_FILTER = 38, 22, 2
LOAD, JEQ, JGE, RET = 0x20, 0x15, 0x35, 0x06  # BPF_LD|W|ABS, BPF_JMP|JEQ|K, ..|JGE|K, RET|K
ALLOW, DENY = 0x7FFF0000, 0x00050000 | EACCES  # SECCOMP_RET_ALLOW, SECCOMP_RET_ERRNO


def filter_program(machine: str) -> bytes | None:
    """The BPF program (struct sock_filter[]) for this machine, None when unknown."""
    found = ARCHITECTURES.get(machine)
    if found is None:
        return None
    arch, socket_nr, uring_nr, x32 = found
    # (code, jump if true, jump if false, k): jumps skip that many instructions
    program = [
        (LOAD, 0, 0, 4),  # seccomp_data.arch
        (JEQ, 1, 0, arch),
        (RET, 0, 0, DENY),  # a foreign ABI (32-bit calls): nothing
        (LOAD, 0, 0, 0),  # seccomp_data.nr
        (JGE, 5, 0, x32) if x32 else (JEQ, 5, 0, 0xFFFFFFFF),
        (JEQ, 4, 0, uring_nr),
        (JEQ, 0, 2, socket_nr),
        (LOAD, 0, 0, 16),  # args[0] (little-endian low word): the socket's domain
        (JEQ, 0, 1, AF_UNIX),
        (RET, 0, 0, ALLOW),
        (RET, 0, 0, DENY),
    ]
    return b"".join(struct.pack("=HBBI", *op) for op in program)


class SocketFilter:
    """The filter, prepared in the judge (nothing is loaded after fork); `install()`
    runs in the child before it starts Python (subprocess's preexec_fn)."""

    def __init__(self) -> None:
        self.reason = ""
        program = filter_program(platform.machine()) if sys.platform == "linux" else None
        if program is None:
            self.reason = f"no socket filter for {sys.platform} on {platform.machine()}"
            return
        try:
            self._libc = ctypes.CDLL(None, use_errno=True)
            self._prctl = self._libc.prctl
        except (OSError, AttributeError) as err:
            self.reason = f"prctl is not available ({err})"
            return
        self._filters = ctypes.create_string_buffer(program)
        fprog = struct.pack("HxxxxxxP", len(program) // 8, ctypes.addressof(self._filters))
        self._fprog = ctypes.create_string_buffer(fprog)

    @property
    def ready(self) -> bool:
        return not self.reason

    def install(self) -> None:
        if not self.ready:
            return
        for args in (
            (PR_SET_NO_NEW_PRIVS, 1, 0, 0, 0),
            (PR_SET_SECCOMP, SECCOMP_MODE_FILTER, ctypes.addressof(self._fprog), 0, 0),
        ):
            if self._prctl(*(ctypes.c_ulong(a) for a in args)) != 0:
                raise OSError(ctypes.get_errno(), "the socket filter could not be installed")


CHECK = """import socket, sys
try:
    socket.socket(socket.AF_INET, socket.SOCK_STREAM)
except PermissionError:
    sys.exit(0)
sys.exit(1)
"""


@functools.cache
def network_closed(python: str = sys.executable) -> tuple[SocketFilter | None, str]:
    """(the filter, "") when it is installed and refuses a socket in a trial process;
    (None, why not) otherwise. Tried once per judge."""
    found = SocketFilter()
    if not found.ready:
        return None, found.reason
    try:
        trial = subprocess.run(
            [python, "-I", "-S", "-c", CHECK], preexec_fn=found.install,
            capture_output=True, timeout=30,
        )  # fmt: skip
    except (OSError, subprocess.SubprocessError) as err:
        return None, f"the socket filter could not be installed ({err})"
    if trial.returncode != 0:
        return None, "the socket filter did not refuse a socket in a trial"
    return found, ""


# --- ending the user's processes ------------------------------------------------------------
def _uids(pid: int) -> tuple[set[int], bool] | None:
    """(real, effective, saved and file uids, whether a zombie) of pid; None when gone."""
    try:
        text = Path(f"/proc/{pid}/status").read_text()
    except OSError:
        return None
    fields = dict(line.split(":", 1) for line in text.splitlines() if ":" in line)
    try:
        uids = {int(u) for u in fields["Uid"].split()}
    except (KeyError, ValueError):
        return None
    return uids, fields.get("State", "").strip().startswith("Z")


def user_processes(uid: int) -> list[int]:
    """The live processes running with uid (real, effective or saved: a process that made
    itself undumpable still counts); Linux's /proc, [] elsewhere."""
    proc = Path("/proc")
    if not proc.is_dir():
        return []
    found = []
    for entry in proc.iterdir():
        if entry.name.isdigit():
            got = _uids(int(entry.name))
            if got is not None and uid in got[0] and not got[1]:
                found.append(int(entry.name))
    return found


def _kill_if_theirs(pid: int, uid: int) -> None:
    """SIGKILL pid if it still runs as uid: through a pidfd, so that the process checked
    is the process signalled."""
    pidfd_open = getattr(os, "pidfd_open", None)
    send = getattr(signal, "pidfd_send_signal", None)
    try:
        fd = pidfd_open(pid) if pidfd_open and send else None
    except OSError:
        return  # gone
    try:
        got = _uids(pid)
        if got is None or uid not in got[0]:
            return
        if fd is None:
            os.kill(pid, signal.SIGKILL)
        else:
            send(fd, signal.SIGKILL)
    except OSError:
        pass
    finally:
        if fd is not None:
            os.close(fd)


def kill_user(uid: int, seconds: float = KILL_SECONDS) -> bool:
    """SIGKILL every process of uid, from this (root) process, until none is left or
    `seconds` have passed; whether none is left."""
    if uid == 0:
        raise ValueError("uid: the judge never kills root's processes")
    deadline = time.monotonic() + seconds
    while True:
        pids = user_processes(uid)
        if not pids:
            return True
        if time.monotonic() > deadline:
            return False
        for pid in pids:
            _kill_if_theirs(pid, uid)
        time.sleep(0.01)  # the kernel reaps the killed


# --- removing the user's files --------------------------------------------------------------
def _remove(path: str, entry_stat: os.stat_result) -> None:
    try:
        if stat.S_ISDIR(entry_stat.st_mode):
            shutil.rmtree(path)  # its whole content: made there by the user or allowed by it
        else:
            os.unlink(path)
    except OSError:
        pass


def _sweep(folder: str, uid: int, gid: int | None, depth: int, removed: list[str]) -> None:
    try:
        entries = list(os.scandir(folder))
    except OSError:
        return
    for entry in entries:
        try:
            found = entry.stat(follow_symlinks=False)
        except OSError:
            continue
        if found.st_uid == uid:
            _remove(entry.path, found)
            removed.append(entry.path)
        elif stat.S_ISDIR(found.st_mode) and depth > 0:
            others = found.st_mode & stat.S_IWOTH
            group = gid is not None and found.st_gid == gid and found.st_mode & stat.S_IWGRP
            if others or group:  # where the user could make a file
                _sweep(entry.path, uid, gid, depth - 1, removed)


def remove_user_files(
    uid: int, gid: int | None = None, places=TMP_PLACES, depth: int = 8
) -> list[str]:
    """Remove every file and folder owned by uid in `places` (not following links), and
    in the folders there that the user could write; the paths removed. Call it when
    the user's processes are gone."""
    if uid == 0:
        raise ValueError("uid: the judge never removes root's files")
    removed: list[str] = []
    for place in places:
        try:
            if os.path.islink(place) or not os.path.isdir(place):
                continue
        except OSError:
            continue
        _sweep(place, uid, gid, depth, removed)
    return removed


# --- removing the user's System V IPC objects -------------------------------------------------
IPC_KINDS = {"shm": ("shmid", "shmctl"), "msg": ("msqid", "msgctl"), "sem": ("semid", "semctl")}
IPC_RMID = 0


def user_ipc(uid: int) -> list[tuple[str, int]]:
    """(kind, id) of each System V IPC object owned by uid (Linux's /proc/sysvipc)."""
    found = []
    for kind, (id_column, _) in IPC_KINDS.items():
        try:
            lines = Path(f"/proc/sysvipc/{kind}").read_text().splitlines()
        except OSError:
            continue
        if not lines:
            continue
        header = lines[0].split()
        for line in lines[1:]:
            row = dict(zip(header, line.split(), strict=False))
            try:
                if int(row["uid"]) == uid:
                    found.append((kind, int(row[id_column])))
            except (KeyError, ValueError):
                continue
    return found


def remove_user_ipc(uid: int) -> list[tuple[str, int]]:
    """Remove every System V shared memory segment, message queue and semaphore set
    owned by uid; those removed. (Nothing where there is no /proc/sysvipc.)"""
    if uid == 0:
        raise ValueError("uid: the judge never removes root's objects")
    found = user_ipc(uid)
    if not found:
        return []
    libc = ctypes.CDLL(None, use_errno=True)
    removed = []
    for kind, ipc_id in found:
        control = getattr(libc, IPC_KINDS[kind][1])
        args = (ipc_id, 0, IPC_RMID) if kind == "sem" else (ipc_id, IPC_RMID, None)
        if control(*args) == 0:
            removed.append((kind, ipc_id))
    return removed
