"""The machine a benchmark ran on: what its timings depend on besides the code."""

from __future__ import annotations

import os
import platform


def cpu_model() -> str:
    """The processor's name (Linux: /proc/cpuinfo), else what the platform says."""
    try:
        with open("/proc/cpuinfo") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return platform.processor() or platform.machine() or "unknown"


def load_average() -> tuple[float, float, float] | None:
    """The number of runnable processes averaged over 1, 5 and 15 minutes (Unix);
    above the core count, other work competes for the processors."""
    try:
        return os.getloadavg()
    except (AttributeError, OSError):
        return None


def compile_bytecode() -> None:
    """Compile rtpy's modules to bytecode files, as installing a package does, so that
    a timed process loads them instead of compiling every module from source (which
    it does on every start when PYTHONDONTWRITEBYTECODE is set, or the package folder
    is read-only)."""
    import compileall
    from pathlib import Path

    compileall.compile_dir(Path(__file__).resolve().parents[2], quiet=1)


def machine() -> dict:
    """The processor, its cores, the system, the Python and numpy versions and the
    load average."""
    import numpy

    return {
        "cpu": cpu_model(),
        "cores": os.cpu_count(),
        "system": f"{platform.system()} {platform.release()}",
        "python": platform.python_version(),
        "numpy": numpy.__version__,
        "load_average": load_average(),
    }
