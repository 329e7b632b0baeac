"""The sandbox's writable space (rtpy.grading.private_space): as root on Linux, a child
in its own mount namespace writes only into small tmpfs, bounded in files and bytes,
that the real folders never see and that vanish with it; the judge's folders under
them stay readable; where the kernel refuses, the reason is given."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import tempfile
import uuid
from pathlib import Path

import pytest

from rtpy.grading import private_space
from rtpy.grading.private_space import PrivateSpace, covered_places, space_bounded
from rtpy.grading.sandbox import Isolation

from .test_confinement import SANDBOX_PYTHON, user  # noqa: F401 (a fixture)

FILL = """import json, os, sys
token, kept = sys.argv[1], sys.argv[2]
made = {"kept": open(kept).read()}
for place in ("/tmp", "/dev/shm", os.environ["HOME"]):
    size = 0
    try:
        with open(os.path.join(place, token + ".bin"), "wb") as f:
            while size < 2**30:
                f.write(b"x" * 2**20)
                f.flush()
                size += 2**20
    except OSError:
        pass
    folder = os.path.join(place, token)
    n = 0
    try:
        os.mkdir(folder)
        while n < 100000:
            open(os.path.join(folder, str(n)), "w").close()
            n += 1
    except OSError:
        pass
    made[place] = [n, size]
print(json.dumps(made))
"""


@pytest.fixture
def folders(user):  # noqa: F811
    """(work, home) in a folder of /tmp every user may pass through, home the user's."""
    base = Path(tempfile.mkdtemp(prefix="rtpy-space-test-", dir="/tmp"))
    os.chmod(base, 0o755)
    work, home = base / "work", base / "home"
    work.mkdir(mode=0o755)
    home.mkdir(mode=0o700)
    os.chown(home, *user)
    (work / "kept.txt").write_text("the judge's file")
    yield work, home
    shutil.rmtree(base)


def fill(space: PrivateSpace, ids, work: Path, home: Path, token: str) -> dict:
    """Run FILL as the user `ids` in the space (files in /tmp, /dev/shm and home
    until refused); what it made where."""
    kept = work / "kept.txt"
    child = space.for_child([work], home, ids)
    proc = subprocess.run(
        [SANDBOX_PYTHON, "-I", "-c", FILL, token, str(kept)], cwd=work,
        env={"HOME": str(home), "PATH": "/usr/bin:/bin"}, capture_output=True, text=True,
        preexec_fn=Isolation(file_mb=None).preexec(child, ids, work), timeout=120,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout)


def test_the_space_is_bounded_private_and_gone(user, folders):  # noqa: F811
    space, why = space_bounded()
    if space is None:
        pytest.skip(f"no private space here: {why}")
    small = PrivateSpace(space.places, megabytes=4, files=300)
    work, home = folders
    token = f"rtpy-space-{uuid.uuid4().hex[:8]}"
    made = fill(small, user, work, home, token)
    assert made["kept"] == "the judge's file"  # a kept folder under /tmp is still there
    for place in ("/tmp", "/dev/shm", str(home)):
        files, size = made[place]
        assert 0 < files < small.files, (place, files)  # the folder and the .bin count too
        assert 0 < size <= small.megabytes * 2**20, (place, size)
        assert not (Path(place) / token).exists(), f"{place}/{token} reached the real folder"
        assert not (Path(place) / f"{token}.bin").exists()


def test_without_the_space_the_same_child_fills_the_real_folders(user, folders):  # noqa: F811
    """The test above is fair: its child writes where it is told to when not confined."""
    work, home = folders
    token = f"rtpy-space-{uuid.uuid4().hex[:8]}"
    script = FILL.replace("100000", "500").replace("2**30", "2**22")
    proc = subprocess.run(
        [SANDBOX_PYTHON, "-I", "-c", script, token, str(work / "kept.txt")], cwd=work,
        env={"HOME": str(home), "PATH": "/usr/bin:/bin"}, capture_output=True, text=True,
        user=user[0], group=user[1], extra_groups=[], timeout=120,
    )  # fmt: skip
    assert proc.returncode == 0, proc.stderr
    assert json.loads(proc.stdout)["/tmp"] == [500, 2**22]
    assert len(list((Path("/tmp") / token).iterdir())) == 500


def test_only_the_judges_paths_under_a_place_are_kept():
    space = PrivateSpace(["/tmp", "/dev/shm"])
    child = space.for_child(["/tmp/x/repo", "/opt/python", "/dev/shm/y"], "/tmp/x/home", (5, 6))
    assert child.keep == [os.path.realpath(p) for p in ("/tmp/x/repo", "/dev/shm/y")]
    assert child.options("0700", child.owner) == b"size=64m,nr_inodes=4096,mode=0700,uid=5,gid=6"
    assert covered_places(["/tmp", "/no/such/folder"]) == ["/tmp"]


def test_where_it_cannot_be_had_it_says_why(monkeypatch):
    monkeypatch.setattr(sys, "platform", "darwin")
    assert space_bounded() == (None, "no mount namespaces on darwin")
    monkeypatch.setattr(sys, "platform", "linux")
    monkeypatch.setattr(os, "geteuid", lambda: 1000)
    assert space_bounded() == (None, "a mount namespace needs root")


@pytest.mark.skipif(sys.platform != "linux", reason="fork and mount namespaces")
def test_a_refused_namespace_is_reported_with_its_reason(monkeypatch):
    """As an unprivileged process (here: forked, without CAP_SYS_ADMIN), unshare is
    refused and the trial names the error."""
    pid = os.fork()
    if pid == 0:  # pragma: no cover
        code = 1
        try:
            if os.geteuid() == 0:
                os.setgid(65534)
                os.setuid(65534)
            code = private_space._trial(PrivateSpace(["/tmp"]))
        finally:
            os._exit(code)
    code = os.waitstatus_to_exitcode(os.waitpid(pid, 0)[1])
    assert code in (1, 13), os.strerror(code)  # EPERM or EACCES
