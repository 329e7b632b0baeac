"""rtpy.engine.memory: the peak resident memory of a piece of work, with and without /proc
and the `resource` module."""

from __future__ import annotations

import json
import mmap
import os
import platform
import subprocess
import sys

import numpy as np
import pytest

from rtpy.engine.memory import peak_memory_mb, reset_peak_memory


def touched_pages(megabytes: int) -> mmap.mmap:
    """Fresh anonymous memory, every page written (small pages: the resident size
    grows by exactly this much, whatever the allocator or numpy would reuse)."""
    memory = mmap.mmap(-1, megabytes << 20)
    if hasattr(mmap, "MADV_NOHUGEPAGE"):
        memory.madvise(mmap.MADV_NOHUGEPAGE)
    np.frombuffer(memory, dtype=np.uint8)[::4096] = 1
    return memory


def test_peak_memory_sees_an_allocation_and_a_reset_forgets_it():
    assert peak_memory_mb() > 0
    if not reset_peak_memory():
        pytest.skip("the peak can be reset on Linux only")
    start = peak_memory_mb()
    memory = touched_pages(64)
    grown = peak_memory_mb()
    memory.close()
    reset_peak_memory()
    after_reset = peak_memory_mb()
    assert grown >= start + 60
    assert after_reset < grown - 50
    assert peak_memory_mb(children=True) >= after_reset


def test_import_and_peak_memory_work_without_the_resource_module():
    """Windows has no `resource`: importing the module must not need it, and peak
    memory falls back to what the platform offers (NaN when nothing)."""
    code = (
        "import sys; sys.modules['resource'] = None\n"
        "import builtins, math\n"
        "real_open = builtins.open\n"
        "def no_proc(path, *a, **k):\n"
        "    if str(path).startswith('/proc/'): raise OSError('no /proc')\n"
        "    return real_open(path, *a, **k)\n"
        "from rtpy.engine.memory import peak_memory_mb, reset_peak_memory\n"
        "builtins.open = no_proc\n"
        "print(reset_peak_memory(), math.isnan(peak_memory_mb()), "
        "math.isnan(peak_memory_mb(children=True)))\n"
    )
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert result.returncode == 0, result.stderr
    assert result.stdout.split() == ["False", "True", "True"]


REUSE_CHILD = """
import resource, sys
import numpy as np
from rtpy.engine.memory import reuse_freed_memory

if sys.argv[1] == "reuse" and not reuse_freed_memory():
    print("unsupported")
    sys.exit(0)
np.ones(96 << 17)  # 96 MB, freed at once
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
np.ones(96 << 17)
print(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before)
"""


def child_says(code: str, *mode: str) -> str:
    """What a fresh process running `code` with arguments `mode` prints (the settings
    are process-wide), under glibc's and numpy's own defaults: no malloc thresholds or
    huge-page choice taken from the environment."""
    env = {
        k: v
        for k, v in os.environ.items()
        if not k.startswith(("MALLOC_", "GLIBC_TUNABLES", "NUMPY_MADVISE_HUGEPAGE"))
    }
    return subprocess.run(
        [sys.executable, "-c", code, *mode], capture_output=True, text=True, check=True, env=env
    ).stdout.strip()


def faults_of_a_second_array(mode: str) -> str:
    """The page faults of allocating and filling a 96 MB array a second time."""
    return child_says(REUSE_CHILD, mode)


def test_freed_memory_is_reused_without_faulting_it_in_again():
    found = faults_of_a_second_array("reuse")
    if found == "unsupported":
        assert platform.libc_ver()[0] != "glibc"  # glibc has mallopt
        pytest.skip("the C library keeps its own policy (not glibc)")
    # 96 MB faulted in again would be 24,576 small pages or 48 huge ones; reused, a
    # handful (the array's header, a page the heap grew by).
    assert int(found) < 16
    # The check can fail: without the setting glibc unmaps the freed block.
    assert int(faults_of_a_second_array("default")) >= 16


GIVE_BACK_CHILD = """
import sys
import numpy as np
from rtpy.engine.memory import give_back_freed_memory, reuse_freed_memory

def resident_mb():
    with open("/proc/self/statm") as f:
        return int(f.read().split()[1]) * 4096 / 2**20

if not reuse_freed_memory():
    print("unsupported")
    sys.exit(0)
np.ones(96 << 17)  # 96 MB, freed at once and kept
kept = resident_mb()
if sys.argv[1] == "give back":
    give_back_freed_memory()
print(kept - resident_mb())
"""


def test_freed_memory_kept_for_reuse_is_given_back():
    given_back = child_says(GIVE_BACK_CHILD, "give back")
    if given_back == "unsupported":
        assert platform.libc_ver()[0] != "glibc"  # glibc has mallopt and malloc_trim
        pytest.skip("the C library keeps its own policy (not glibc)")
    assert float(given_back) >= 90  # of the 96 MB freed
    # The check can fail: kept, the freed block stays resident.
    assert float(child_says(GIVE_BACK_CHILD, "keep")) < 5


PAGES_CHILD = """
import resource, sys
from rtpy.engine.memory import small_pages_for_numpy

if sys.argv[1] == "small":
    small_pages_for_numpy()
import numpy as np

if sys.argv[1] == "small" and not sys.platform.startswith("linux"):
    print("unsupported")
    sys.exit(0)
before = resource.getrusage(resource.RUSAGE_SELF).ru_minflt
np.ones(96 << 17)  # 96 MB, fresh
print(resource.getrusage(resource.RUSAGE_SELF).ru_minflt - before)
"""
SMALL_PAGES = (96 << 20) // 4096


def huge_pages_on_request() -> bool:
    """The kernel gives transparent huge pages to memory that asks for them only."""
    try:
        with open("/sys/kernel/mm/transparent_hugepage/enabled") as f:
            return "[madvise]" in f.read()
    except OSError:
        return False


def faults_of_a_fresh_array(mode: str) -> str:
    """The page faults of allocating and filling a fresh 96 MB array."""
    return child_says(PAGES_CHILD, mode)


def test_numpy_arrays_get_small_pages():
    """small_pages_for_numpy: a fresh 96 MB array is faulted in by 4 kB pages, as many
    faults as pages, not by 48 huge ones the kernel may compact memory to find."""
    found = faults_of_a_fresh_array("small")
    if found == "unsupported":
        assert not sys.platform.startswith("linux")  # numpy asks for huge pages on Linux
        pytest.skip("numpy asks for no huge pages here")
    if not huge_pages_on_request():
        pytest.skip("the kernel's huge pages are not given on request")
    assert int(found) >= SMALL_PAGES  # numpy's default here: 49 faults (huge pages)


# A library call in someone else's interpreter: every way rtpy could change the
# process's allocator is recorded (glibc's mallopt and malloc_trim through ctypes,
# numpy's private huge-page switch), then both backends render, in this process and
# with forked workers.
LIBRARY_CALL_CHILD = """
import ctypes, json, os, sys
calls = []

class RecordingCDLL(ctypes.CDLL):
    def __getattr__(self, name):
        if name in ("mallopt", "malloc_trim"):
            calls.append(name)
        return super().__getattr__(name)

ctypes.CDLL = RecordingCDLL
from numpy._core import multiarray
real_switch = getattr(multiarray, "_set_madvise_hugepage", None)

def switch(enabled):
    calls.append("_set_madvise_hugepage")
    return real_switch(enabled)

multiarray._set_madvise_hugepage = switch
environment = dict(os.environ)
import rtpy

ball = rtpy.Sphere(rtpy.Vec3(0, 0, -1), 0.5, rtpy.Lambertian())
scene, camera = rtpy.Scene([ball], sky=True), rtpy.Camera(width=16)
for backend in ("scalar", "numpy"):
    for workers in (1, 2):
        rtpy.render(scene, camera=camera, spp=2, backend=backend, workers=workers)
if sys.argv[-1] == "main":  # the command line's main() called from Python, too
    from rtpy.cli.main import main

    out = os.path.join(sys.argv[-2], "out.png")
    main(["render", "cornell", "--width", "8", "--spp", "1", "-j", "2", "-q", "-o", out])
names = set(os.environ) | set(environment)
changed = sorted(k for k in names if os.environ.get(k) != environment.get(k))
print(json.dumps([calls, changed]))
"""


@pytest.mark.skipif(sys.platform == "win32", reason="Windows cannot fork")
def test_a_library_render_changes_nothing_process_wide():
    """import rtpy; rtpy.render(...) in a fresh interpreter, either backend, with and
    without workers, sets no allocator option and no environment variable."""
    calls, changed = json.loads(child_says(LIBRARY_CALL_CHILD, "library"))
    assert calls == []
    assert changed == []


@pytest.mark.skipif(sys.platform == "win32", reason="Windows cannot fork")
def test_the_command_lines_main_called_from_python_changes_nothing_either(tmp_path):
    """rtpy.cli.main.main(["render", ...]) in someone else's interpreter: the tuning
    is the command-line process's own (rtpy/__main__.py, the `rtpy` script)."""
    calls, changed = json.loads(child_says(LIBRARY_CALL_CHILD, str(tmp_path), "main"))
    assert calls == []
    assert changed == []
