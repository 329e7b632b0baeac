"""rtpy's version: the installed package's (pyproject.toml's), looked up only when
asked for (importlib.metadata takes a few tens of milliseconds to load)."""

from __future__ import annotations

from functools import cache

__all__ = ["version"]


@cache
def version() -> str:
    """The installed rtpy's version; "0+unknown" in a source tree never installed."""
    from importlib.metadata import PackageNotFoundError
    from importlib.metadata import version as installed

    try:
        return installed("rtpy")
    except PackageNotFoundError:
        return "0+unknown"
