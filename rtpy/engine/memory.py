"""Peak memory: the most resident memory a piece of work used, for a render's
stats (image.stats["peak_rss_mb"]) and `rtpy bench`.

Linux reads the kernel's high-water mark (/proc/self/status), which
reset_peak_memory() resets; elsewhere getrusage's maximum since the process
started. The module imports `resource` only when asked (Windows has none).

Tuning, for rtpy's own processes only (`python -m rtpy` and its workers; a library
call such as rtpy.render changes nothing process-wide): it took the first render of
the 1M-triangle OBJ scene from 2.95 s to 2.2 s and of its PLY twin from 1.9 s to
1.4 s (docs/performance.md#scene-size). The command line's process (`python -m rtpy`, the
`rtpy` script; not rtpy.cli.main.main called from Python) calls both at its start,
before numpy is imported: glibc
keeps freed memory for the next array (reuse_freed_memory), numpy backs its arrays
with ordinary pages, and the workers it starts get both through the documented
environment variables. A render that forks its workers from such a process hands the
kept memory back first (give_back_freed_memory).
"""

from __future__ import annotations

import math
import os
import sys

__all__ = [
    "give_back_freed_memory",
    "max_rss_mb",
    "peak_memory_mb",
    "reset_peak_memory",
    "reuse_freed_memory",
    "small_pages_for_numpy",
    "tune_for_large_scenes",
]

# mallopt(3) parameters, from glibc's malloc.h
M_TRIM_THRESHOLD = -1
M_MMAP_THRESHOLD = -3
KEEP_BYTES = 1 << 30  # blocks up to this size come from the heap and stay there

_kept = False  # whether reuse_freed_memory has set this process to keep freed memory


def reset_peak_memory() -> bool:
    """Start measuring a new peak: reset the kernel's high-water mark of this
    process's resident memory (Linux). False where that is not possible; then
    peak_memory_mb reports the peak since the process started."""
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
        return True
    except OSError:
        return False


def _high_water_mark_mb() -> float | None:
    """VmHWM of /proc/self/status (Linux): the peak since start or the last reset."""
    try:
        with open("/proc/self/status") as f:
            for line in f:
                if line.startswith("VmHWM:"):
                    return int(line.split()[1]) / 1024.0
    except (OSError, ValueError, IndexError):
        pass
    return None


def max_rss_mb(children: bool) -> float:
    """getrusage's ru_maxrss in MB (kilobytes on Linux, bytes on macOS): the peak of this
    process since it started, or with children=True of its largest finished child; NaN
    without the `resource` module (Windows)."""
    try:
        import resource
    except ImportError:
        return math.nan
    who = resource.RUSAGE_CHILDREN if children else resource.RUSAGE_SELF
    value = resource.getrusage(who).ru_maxrss
    return value / (1024.0 * 1024.0) if sys.platform == "darwin" else value / 1024.0


def peak_memory_mb(children: bool = False) -> float:
    """Peak resident memory in MB of this process: since the last
    reset_peak_memory() on Linux, since the process started elsewhere. With
    children=True, the largest finished child process (a render's workers) counts
    too. NaN where the platform reports neither."""
    own = _high_water_mark_mb()
    if own is None:
        own = max_rss_mb(children=False)
    if not children:
        return own
    known = [mb for mb in (own, max_rss_mb(children=True)) if not math.isnan(mb)]
    return max(known, default=math.nan)


def reuse_freed_memory(mmap_threshold: int = KEEP_BYTES, trim_threshold: int = KEEP_BYTES) -> bool:
    """Have freed memory kept for the next allocation rather than given back to the
    system at once (glibc's malloc, on Linux): blocks up to mmap_threshold bytes come
    from the heap, and freed memory at its top is given back only past trim_threshold
    bytes. True where that was set.

    glibc gives every block larger than its mmap threshold (at most 32 MB) pages of
    its own and unmaps them when the block is freed, so the next array that size is
    faulted in again page by page. Reading and building a million-triangle mesh makes
    hundreds of such temporaries, and their page faults took a quarter of a first
    render's time (docs/performance.md#scene-size). With both thresholds at 1 GiB the
    temporaries reuse the heap; the peak resident size grows a little, since freed
    blocks are not given back (565 MB against 542 MB for that render).
    Elsewhere (macOS, Windows, musl) nothing is changed and False is returned.
    """
    global _kept
    mallopt = _c_library_function("mallopt", "c_int", "c_int")
    if mallopt is None:
        return False
    _kept = bool(mallopt(M_MMAP_THRESHOLD, mmap_threshold)) and bool(
        mallopt(M_TRIM_THRESHOLD, trim_threshold)
    )
    return _kept


def give_back_freed_memory() -> bool:
    """Give the pages of freed heap blocks back to the system (glibc's malloc_trim)
    in a process that reuse_freed_memory set to keep them; True where that was done.
    Anywhere else (a library call's host process) nothing is done: glibc gives freed
    memory back by itself there.

    After reading and building a million-triangle mesh, reuse_freed_memory leaves
    about 380 MB of freed blocks resident. Worker processes forked then share those
    pages with this process, and a worker writing an array into one copies each page
    it touches (copy-on-write); given back, the page is a fresh zero page instead.
    Giving them back took 26 ms here and made a first render of that mesh with two
    workers about 0.05 s faster (docs/performance.md#scene-size); this process stays
    at 134 MB rather than 516 MB while the workers render.
    Elsewhere (macOS, Windows, musl) nothing is done and False is returned.
    """
    malloc_trim = _c_library_function("malloc_trim", "c_size_t") if _kept else None
    if malloc_trim is None:
        return False
    malloc_trim(0)
    return True


def _c_library_function(name: str, *argument_types: str):
    """The C library's function `name` (Linux), taking arguments of the given ctypes
    types and returning an int; None elsewhere or where the library has none."""
    if not sys.platform.startswith("linux"):
        return None
    import ctypes

    try:
        function = getattr(ctypes.CDLL(None), name)
    except (OSError, AttributeError):
        return None
    function.argtypes = [getattr(ctypes, t) for t in argument_types]
    function.restype = ctypes.c_int
    return function


def small_pages_for_numpy() -> None:
    """Have numpy back its arrays with ordinary 4 kB pages in this process, if numpy is
    not imported yet, and in the processes it starts: numpy's documented
    NUMPY_MADVISE_HUGEPAGE=0, unless the user set it.

    On Linux numpy asks the kernel to back arrays of 4 MB or more with 2 MB pages;
    where transparent huge pages are given on request (the usual "madvise" setting),
    the kernel finds a free 2 MB page at the first touch of each, compacting memory if
    it must, while the process waits. A first render of a million triangles from
    binary PLY spent about 1 s of system time so (docs/performance.md#scene-size).
    Elsewhere numpy never asks, and the variable changes nothing.
    """
    os.environ.setdefault("NUMPY_MADVISE_HUGEPAGE", "0")


def tune_for_large_scenes() -> None:
    """The memory policy of the command line's renders: reuse_freed_memory here, and
    the same thresholds for the workers it starts by running Python afresh (spawn,
    forkserver) through glibc's documented MALLOC_MMAP_THRESHOLD_ and
    MALLOC_TRIM_THRESHOLD_ (forked workers inherit the setting). It lets a
    million-triangle mesh be read and built without page faults dominating; a no-op
    where the platform offers nothing of the kind. Never called by a library call."""
    if reuse_freed_memory():
        os.environ.setdefault("MALLOC_MMAP_THRESHOLD_", str(KEEP_BYTES))
        os.environ.setdefault("MALLOC_TRIM_THRESHOLD_", str(KEEP_BYTES))
