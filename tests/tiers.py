"""The two tiers of the suite: `python -m pytest` runs every test, `python -m pytest -m
"not slow"` (the everyday loop) leaves out those marked slow. A long parametrized test
keeps a representative case or two in the fast tier and the rest in the slow one."""

from __future__ import annotations

import pytest


def slow_except(cases, *fast) -> list:
    """The parameter sets `cases` (tuples, or single values) for pytest.mark.parametrize,
    each marked slow except those equal to one of `fast`."""
    cases = list(cases)
    missing = [f for f in fast if f not in cases]
    if missing:
        raise ValueError(f"fast cases {missing} are not among the cases {cases}")
    return [
        pytest.param(*(c if isinstance(c, tuple) else (c,)), marks=() if c in fast else SLOW)
        for c in cases
    ]


SLOW = (pytest.mark.slow,)


# path of a collected test file -> it has a test not marked slow
FAST_TESTS = pytest.StashKey[dict[str, bool]]()


def record_fast_tests(config, items) -> None:
    """Record in config.stash[FAST_TESTS] the files of the collected items, and whether
    each has one outside the slow tier (called before -m deselects any)."""
    fast = config.stash.setdefault(FAST_TESTS, {})
    for item in items:
        path = item.path.as_posix()
        fast[path] = fast.get(path, False) or item.get_closest_marker("slow") is None
