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
