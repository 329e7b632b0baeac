"""Shared test configuration.

Hypothesis explores new random examples on every local run; under CI (CI=true)
it is derandomized, so a CI run is reproducible and never fails by chance.
Hypothesis also mixes constants from the modules already imported into its examples,
so every rtpy module is imported here first: a test then draws the same examples
whether it runs alone or in the whole suite.

Before -m "not slow" deselects anything, the collected test files are recorded with
whether each has a test outside the slow tier (tests/test_layout.py checks that
every one has).

A full collection of the garbage collector walks every tracked object, and the
session holds a large heap to its end (the imported modules, the collected tests,
hypothesis's state): each one takes tens of milliseconds, and they come often (every
in-process pytest run of the grading tests forces one). So the objects alive after
the imports, after collection and after each test file's last teardown are frozen
(gc.freeze) right after a collection: the collector then walks only what the tests
create since. The collection first means no garbage is kept, only what is alive.
"""

import gc
import importlib
import multiprocessing
import os
import pkgutil

import pytest
from hypothesis import settings

import rtpy

from . import ahead
from .tiers import record_fast_tests

settings.register_profile("ci", derandomize=True, deadline=None, print_blob=True)
settings.register_profile("dev", deadline=None)
settings.load_profile("ci" if os.environ.get("CI") else "dev")

for module in pkgutil.walk_packages(rtpy.__path__, "rtpy."):
    if not module.name.endswith("__main__"):
        importlib.import_module(module.name)


def freeze_what_lives() -> None:
    gc.collect()
    gc.freeze()


freeze_what_lives()


@pytest.hookimpl(tryfirst=True)
def pytest_collection_modifyitems(config, items):
    record_fast_tests(config, items)


def pytest_collection_finish(session):
    freeze_what_lives()
    ahead.start(session)  # the heavy checks, computed ahead at low priority


def pytest_sessionfinish(session):
    ahead.finish()


@pytest.hookimpl(trylast=True)
def pytest_runtest_teardown(item, nextitem):
    """After pytest's teardown of the last test of a file (its module-scoped fixtures
    finalized)."""
    if nextitem is None or nextitem.path != item.path:
        freeze_what_lives()


START_METHODS = ["fork", "spawn", "forkserver"]


@pytest.fixture(params=START_METHODS)
def start_method(request):
    """The default start method forced to each one (Windows and macOS start workers
    by spawn, Linux by fork, and by forkserver from Python 3.14)."""
    before = multiprocessing.get_start_method(allow_none=True)
    multiprocessing.set_start_method(request.param, force=True)
    yield request.param
    multiprocessing.set_start_method(before, force=True)


@pytest.fixture(autouse=True)
def plugins_of_this_test_only():
    """A plugin a test loads is forgotten after it (rtpy.engine.plugins.PLUGINS, which
    worker processes load again): its file lives in the test's tmp_path, which is
    removed once the test passes (pyproject.toml's tmp_path_retention_policy)."""
    from rtpy.engine.plugins import PLUGINS

    saved = dict(PLUGINS)
    yield
    PLUGINS.clear()
    PLUGINS.update(saved)
