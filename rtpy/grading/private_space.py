"""The sandbox's writable space, bounded: a mount namespace of its own (Linux, root).

`PrivateSpace.enter()` runs in the child before it drops root and starts Python
(sandbox.Isolation.preexec): it unshares the mount namespace, makes every mount in it
private (nothing propagates back), and mounts a small tmpfs (MEGABYTES, FILES) over
each folder any user may write (PLACES) and over the sandbox's home. What the student's
code writes there never reaches the disk, cannot exceed the bound in bytes or in
files, and is gone when the child's last process ends (the namespace ends with it);
no later run sees it. The judge's own folders that lie under a covered place (the
work copy, the child's configuration, the Python it runs) are bound back in first,
at the same path.

Where the kernel refuses (another OS, not root, a container without CAP_SYS_ADMIN),
`space_bounded` says why, once, and the judge falls back to what holds without it:
a bound on each file's size (RLIMIT_FSIZE) and the removal of the user's files at
the end (rtpy.grading.confinement).
"""

from __future__ import annotations

import ctypes
import functools
import os
import sys
from dataclasses import dataclass, field
from pathlib import Path

PLACES = ("/tmp", "/var/tmp", "/dev/shm", "/run/lock")  # (/var/lock is usually a link)
MEGABYTES = 64  # each mount's bytes ...
FILES = 4096  # ... and files (inodes: folders count too)
CLONE_NEWNS = 0x00020000
MS_NOSUID, MS_NODEV, MS_BIND, MS_REC, MS_PRIVATE = 0x2, 0x4, 0x1000, 0x4000, 0x40000


def _covered(path: str, places: list[str]) -> bool:
    return any(path == p or path.startswith(p.rstrip("/") + "/") for p in places)


@dataclass
class PrivateSpace:
    """The mounts of one child. places: the real folders covered; keep: the judge's
    paths under them that stay visible (folders or files); home: the sandbox's own
    folder, a tmpfs of its user (uid, gid)."""

    places: list[str]
    megabytes: int = MEGABYTES
    files: int = FILES
    keep: list[str] = field(default_factory=list)
    home: str | None = None
    owner: tuple[int, int] | None = None

    def __post_init__(self) -> None:
        self._libc = ctypes.CDLL(None, use_errno=True)  # loaded here: not after fork

    def for_child(self, keep, home: Path | None, owner: tuple[int, int] | None) -> PrivateSpace:
        """The same bound for a child: `keep` (paths) bound back in, home its user's."""
        real = [os.path.realpath(k) for k in keep]
        return PrivateSpace(
            self.places, self.megabytes, self.files,
            keep=[k for k in real if _covered(k, self.places)],
            home=None if home is None else os.path.realpath(home), owner=owner,
        )  # fmt: skip

    def options(self, mode: str, owner: tuple[int, int] | None = None) -> bytes:
        text = f"size={self.megabytes}m,nr_inodes={self.files},mode={mode}"
        if owner is not None:
            text += f",uid={owner[0]},gid={owner[1]}"
        return text.encode()

    def _mount(self, source: str, target: str, fstype: str | None, flags: int, data) -> None:
        found = self._libc.mount(
            source.encode(), target.encode(), fstype and fstype.encode(),
            ctypes.c_ulong(flags), data,
        )  # fmt: skip
        if found != 0:
            errno = ctypes.get_errno()
            raise OSError(errno, f"mount {target}: {os.strerror(errno)}")

    def enter(self) -> None:
        """In the child, as root: the new namespace and its mounts (OSError when the
        kernel refuses)."""
        if self._libc.unshare(CLONE_NEWNS) != 0:
            errno = ctypes.get_errno()
            raise OSError(errno, f"unshare: {os.strerror(errno)}")
        self._mount("none", "/", None, MS_REC | MS_PRIVATE, None)
        kept = [(k, os.open(k, os.O_PATH)) for k in sorted(set(self.keep))]
        for place in self.places:
            self._mount("tmpfs", place, "tmpfs", MS_NOSUID | MS_NODEV, self.options("1777"))
        done: list[str] = []
        for path, fd in kept:
            if not _covered(path, done):  # inside one bound already: visible
                _make_target(path, fd)
                self._mount(f"/proc/self/fd/{fd}", path, None, MS_BIND | MS_REC, None)
                done.append(path)
            os.close(fd)
        if self.home is not None:
            os.makedirs(self.home, mode=0o711, exist_ok=True)
            options = self.options("0700", self.owner)
            self._mount("tmpfs", self.home, "tmpfs", MS_NOSUID | MS_NODEV, options)


def _make_target(path: str, fd: int) -> None:
    """An empty folder or file at path (in the new tmpfs), to mount fd's over."""
    if os.path.isdir(f"/proc/self/fd/{fd}"):
        os.makedirs(path, mode=0o711, exist_ok=True)
    else:
        os.makedirs(os.path.dirname(path), mode=0o711, exist_ok=True)
        os.close(os.open(path, os.O_CREAT | os.O_WRONLY, 0o600))


def covered_places(places=PLACES) -> list[str]:
    """The places that are real folders here (not links, which lead to one of them)."""
    return [p for p in places if os.path.isdir(p) and not os.path.islink(p)]


TRIAL_FAILED = 127


def _trial(space: PrivateSpace) -> int:
    """In a forked child: 0 when the mounts are made and bound as asked, else an errno
    (or TRIAL_FAILED)."""
    try:
        space.enter()
        for place in space.places:
            if os.statvfs(place).f_files != space.files:
                return TRIAL_FAILED
        return 0
    except OSError as err:
        return err.errno if err.errno and 0 < err.errno < TRIAL_FAILED else TRIAL_FAILED
    except BaseException:
        return TRIAL_FAILED


def space_bounded() -> tuple[PrivateSpace | None, str]:
    """(the space, "") when this judge can give a child its private bounded space;
    (None, why not) otherwise."""
    if sys.platform != "linux":
        return None, f"no mount namespaces on {sys.platform}"
    if os.geteuid() != 0:
        return None, "a mount namespace needs root"
    return _tried(tuple(covered_places()))


@functools.cache
def _tried(places: tuple[str, ...]) -> tuple[PrivateSpace | None, str]:
    """The space over places, tried once per judge in a forked process."""
    try:
        space = PrivateSpace(list(places))
    except OSError as err:
        return None, f"the C library is not available ({err})"
    pid = os.fork()
    if pid == 0:  # pragma: no cover (the forked child)
        os._exit(_trial(space))
    code = os.waitstatus_to_exitcode(os.waitpid(pid, 0)[1])
    if code == 0:
        return space, ""
    why = os.strerror(code) if 0 < code < TRIAL_FAILED else "the trial's mounts were not made"
    return None, f"the kernel refused a private mount namespace with tmpfs ({why})"
