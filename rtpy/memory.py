"""Peak memory: the most resident memory a piece of work used, for a render's
stats (image.stats["peak_rss_mb"]) and `rtpy bench`.

Linux reads the kernel's high-water mark (/proc/self/status), which
reset_peak_memory() resets; elsewhere getrusage's maximum since the process
started. The module imports `resource` only when asked (Windows has none).
"""

from __future__ import annotations

import math
import sys

__all__ = ["max_rss_mb", "peak_memory_mb", "reset_peak_memory"]


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
