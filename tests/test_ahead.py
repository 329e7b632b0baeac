"""tests/ahead.py: heavy checks computed ahead in a background process give the
outcomes the module's fixture would compute, and what is missing is computed there."""

from __future__ import annotations

from .ahead import Ahead, key
from .cores import module_outcomes, run_check


def square(x: int) -> int:
    return x * x


def fails(x: int) -> None:
    assert x < 0, f"{x} is not negative"


def raises(x: int) -> None:
    raise ValueError(x)


# The checks the background process finds by importing this module.
toy = module_outcomes({"test_square": square, "test_fails": fails, "test_raises": raises})
MODULE = __name__


def work(test: str, values: list[int]) -> list:
    return [(key(MODULE, test, {"x": x}), MODULE, test, {"x": x}) for x in values]


def test_outcomes_computed_ahead_are_the_checks_outcomes():
    items = work("test_square", [2, 3])
    ahead = Ahead(items)
    try:
        assert ahead.process is not None
        ahead.process.wait(timeout=60)
        keys = [k for k, *_ in items]
        assert (
            ahead.take(keys)
            == {keys[0]: 4, keys[1]: 9}
            == {k: run_check((square, params)) for k, _, _, params in items}
        )
    finally:
        ahead.close()
    assert not ahead.folder.exists()


def test_a_check_that_fails_or_raises_is_left_to_the_fixture():
    """Computed again in pytest's process, whose assertion rewriting explains it."""
    items = work("test_fails", [5]) + work("test_raises", [1]) + work("test_square", [4])
    ahead = Ahead(items)
    try:
        ahead.process.wait(timeout=60)
        keys = [k for k, *_ in items]
        assert ahead.take(keys) == {keys[2]: 16}
    finally:
        ahead.close()


def test_missing_outcomes_stop_the_process_and_the_rest_goes_on():
    """A fixture asking for outcomes not there yet: the process is stopped, started
    again without them, and computes the others."""
    first, later = work("test_square", [7]), work("test_square", [8])
    ahead = Ahead(first + later)
    try:
        ahead.stop()  # as if the fixture came before anything was computed
        ahead.done.clear()
        [(k, *_)] = first
        ahead.take([k])  # the caller computes this one
        assert ahead.process is not None  # started again for the later one
        ahead.process.wait(timeout=60)
        [(k_later, *_)] = later
        assert ahead.take([k_later]) == {k_later: 64}
    finally:
        ahead.close()
