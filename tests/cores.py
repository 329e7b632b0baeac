"""Independent heavy checks of a test module run on both cores of the machine.

The checks are pure Python (threads would take turns), so they run in forked
processes, one per core. Each test still asserts on its own outcome, so a failure is
reported on the test (and the parameters) it belongs to. In a long run the checks of
module_outcomes are computed ahead, in the background (tests/ahead.py).
"""

from __future__ import annotations

import multiprocessing
import os
import signal
import sys
import traceback
from collections.abc import Callable
from typing import Any, TypeVar

import pytest

from . import ahead

T, R = TypeVar("T"), TypeVar("R")


def on_every_core(function: Callable[[T], R], items: list[T]) -> list[R]:
    """[function(x) for x in items], in forked processes, one per core, where the
    system forks; the items are handed out in order, one at a time, so the longest
    ones listed first keep both cores busy to the end."""
    workers = min(len(items), os.cpu_count() or 1)
    if workers > 1 and "fork" in multiprocessing.get_all_start_methods():
        # SIGTERM as by default in the workers, whatever handler the tests' process
        # has: the pool ends them with it
        context = multiprocessing.get_context("fork")
        with context.Pool(workers, signal.signal, (signal.SIGTERM, signal.SIG_DFL)) as pool:
            return pool.map(function, items, chunksize=1)
    return [function(x) for x in items]


# test module -> the checks of its module_outcomes (which tests/ahead.py computes ahead)
CHECKS: dict[str, dict[str, Callable[..., Any]]] = {}


def run_check(call: tuple[Callable[..., Any], dict]) -> Any:
    check, params = call
    try:
        return check(**params)
    except AssertionError as error:  # raised again by outcome(), on its own test
        if not str(error):  # a bare assert of a helper: its traceback stays here
            frame = traceback.extract_tb(error.__traceback__)[-1]
            error.args = (f"{frame.filename}:{frame.lineno}: {frame.line}",)
        return error


def selected_checks(request, checks: dict[str, Callable[..., R]]) -> dict[str, R]:
    """For a module-scoped fixture: node id -> the outcome of checks[test](**params) for
    every test of the fixture's module named in `checks` that this session runs, with
    that test's parameters (or the AssertionError it raised). All of them run on every
    core, the tests in the order of `checks` (list the longest first); tests whose check
    is the same function with the same parameters share one run of it. The checks are
    module-level functions (the forked workers receive them pickled)."""
    order = list(checks)
    items = sorted(
        (
            item
            for item in request.session.items
            if item.module is request.module and item.originalname in checks
        ),
        key=lambda item: order.index(item.originalname),
    )
    calls = [(checks[item.originalname], params_of(item)) for item in items]
    keys = [(check, repr(sorted(params.items()))) for check, params in calls]
    distinct = dict(zip(keys, calls, strict=True))
    outcomes = _computed_ahead(request.module.__name__, items, keys)
    missing = [k for k in distinct if k not in outcomes]
    outcomes.update(
        zip(missing, on_every_core(run_check, [distinct[k] for k in missing]), strict=True)
    )
    return {item.nodeid: outcomes[key] for item, key in zip(items, keys, strict=True)}


def _computed_ahead(module: str, items: list, keys: list) -> dict:
    """key -> outcome, of the checks tests/ahead.py has computed (named there by module,
    function and parameters, across processes)."""
    registered = CHECKS.get(module, {})
    names = {
        k: ahead.key(module, item.originalname, params_of(item))
        for item, k in zip(items, keys, strict=True)
        if item.originalname in registered
    }
    known = ahead.take(list(dict.fromkeys(names.values())))
    return {k: known[name] for k, name in names.items() if name in known}


def module_outcomes(checks: dict[str, Callable[..., Any]]):
    """A module-scoped fixture, named by the test module's variable that holds it:
    selected_checks(request, checks), whose outcomes tests/ahead.py may compute ahead."""
    CHECKS.setdefault(sys._getframe(1).f_globals["__name__"], {}).update(checks)

    @pytest.fixture(scope="module")
    def outcomes(request) -> dict[str, Any]:
        return selected_checks(request, checks)

    return outcomes


def params_of(item) -> dict:
    callspec = getattr(item, "callspec", None)
    return dict(callspec.params) if callspec is not None else {}


def outcome(outcomes: dict[str, R], request) -> R:
    """The outcome of the requesting test in selected_checks' `outcomes`; the assertion
    error of its check raised here."""
    result = outcomes[request.node.nodeid]
    if isinstance(result, AssertionError):
        raise result
    return result
