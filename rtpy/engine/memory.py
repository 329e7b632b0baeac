"""Peak memory: the most resident memory a piece of work used, for a render's
stats (image.stats["peak_rss_mb"]) and `rtpy bench`.

Linux reads the kernel's high-water mark (/proc/self/status), which
reset_peak_memory() resets; elsewhere getrusage's maximum since the process
started. The module imports `resource` only when asked (Windows has none).

tune_for_large_scenes(), which a render calls before it loads its scene, tells the
C library to keep freed memory for the next array (reuse_freed_memory) and numpy
to back its arrays with ordinary pages (avoid_huge_pages). A render that forks its
workers hands that kept memory back first (give_back_freed_memory).
"""

from __future__ import annotations

import math
import sys

__all__ = [
    "avoid_huge_pages",
    "give_back_freed_memory",
    "max_rss_mb",
    "peak_memory_mb",
    "reset_peak_memory",
    "reuse_freed_memory",
    "tune_for_large_scenes",
]

# mallopt(3) parameters, from glibc's malloc.h
M_TRIM_THRESHOLD = -1
M_MMAP_THRESHOLD = -3
KEEP_BYTES = 1 << 30  # blocks up to this size come from the heap and stay there


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
    mallopt = _c_library_function("mallopt", "c_int", "c_int")
    if mallopt is None:
        return False
    return bool(mallopt(M_MMAP_THRESHOLD, mmap_threshold)) and bool(
        mallopt(M_TRIM_THRESHOLD, trim_threshold)
    )


def give_back_freed_memory() -> bool:
    """Give the pages of freed heap blocks back to the system (glibc's malloc_trim);
    True where that was done.

    After reading and building a million-triangle mesh, reuse_freed_memory leaves
    about 380 MB of freed blocks resident. Worker processes forked then share those
    pages with this process, and a worker writing an array into one copies each page
    it touches (copy-on-write); given back, the page is a fresh zero page instead.
    Giving them back took 26 ms here and made a first render of that mesh with two
    workers about 0.05 s faster (docs/performance.md#scene-size); this process stays
    at 134 MB rather than 516 MB while the workers render.
    Elsewhere (macOS, Windows, musl) nothing is done and False is returned.
    """
    malloc_trim = _c_library_function("malloc_trim", "c_size_t")
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


def avoid_huge_pages() -> bool:
    """Stop numpy from asking the kernel (Linux) to back its arrays of 4 MB or more
    with 2 MB pages; True where numpy asked until now.

    Where transparent huge pages are given on request (the usual "madvise" setting),
    the kernel finds a free 2 MB page at the first touch of each, compacting memory
    if it must, while the process waits. A first render of a million triangles from
    binary PLY spent about 1 s of system time so (docs/performance.md#scene-size):
    2.0 s in all against 1.4 s with ordinary 4 kB pages. Elsewhere numpy never asks,
    and False is returned.
    """
    if not sys.platform.startswith("linux"):
        return False
    try:
        from numpy._core import multiarray
    except ImportError:  # numpy 1
        from numpy.core import multiarray
    set_advice = getattr(multiarray, "_set_madvise_hugepage", None)
    return False if set_advice is None else bool(set_advice(False))


def tune_for_large_scenes() -> None:
    """The memory policy of a render (reuse_freed_memory and avoid_huge_pages), which
    lets a million-triangle mesh be read and built without page faults dominating;
    a no-op where the platform offers neither."""
    reuse_freed_memory()
    avoid_huge_pages()
