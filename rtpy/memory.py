"""Peak memory: the most resident memory a piece of work used, for a render's
stats (image.stats["peak_rss_mb"]) and `rtpy bench`.

Linux reads the kernel's high-water mark (/proc/self/status), which
reset_peak_memory() resets; elsewhere getrusage's maximum since the process
started. The module imports `resource` only when asked (Windows has none).

reuse_freed_memory() tells the C library to keep freed memory for the next array,
which a render calls before it loads its scene.
"""

from __future__ import annotations

import math
import sys

__all__ = ["max_rss_mb", "peak_memory_mb", "reset_peak_memory", "reuse_freed_memory"]

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


def reuse_freed_memory() -> bool:
    """Have freed memory kept for the next allocation rather than given back to the
    system at once (glibc's malloc, on Linux); True where that was set.

    glibc gives every block larger than its mmap threshold (at most 32 MB) pages of
    its own and unmaps them when the block is freed, so the next array that size is
    faulted in again page by page. Reading and building a million-triangle mesh makes
    hundreds of such temporaries, and their page faults took a quarter of a first
    render's time (docs/performance.md#scene-size). With both thresholds at 1 GiB the
    temporaries reuse the heap; the peak resident size grows a little, since freed
    blocks are not given back (565 MB against 542 MB for that render).
    Elsewhere (macOS, Windows, musl) nothing is changed and False is returned.
    """
    if not sys.platform.startswith("linux"):
        return False
    import ctypes

    try:
        mallopt = ctypes.CDLL(None).mallopt
    except (OSError, AttributeError):
        return False
    mallopt.argtypes = [ctypes.c_int, ctypes.c_int]
    mallopt.restype = ctypes.c_int
    return bool(mallopt(M_MMAP_THRESHOLD, KEEP_BYTES)) and bool(
        mallopt(M_TRIM_THRESHOLD, KEEP_BYTES)
    )
