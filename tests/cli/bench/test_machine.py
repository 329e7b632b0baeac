"""rtpy.cli.bench.machine: what a benchmark's timings depend on besides the code."""

from __future__ import annotations

import importlib.util
import os
import platform
import sys
from pathlib import Path

import numpy as np

import rtpy
from rtpy.cli.bench.machine import compile_bytecode, cpu_model, load_average, machine


def test_machine_names_cpu_cores_versions_and_load():
    m = machine()
    assert m["cpu"] == cpu_model() and m["cpu"]
    assert m["cores"] == os.cpu_count() and m["cores"] >= 1
    assert m["python"] == platform.python_version() and m["numpy"] == np.__version__
    load = m["load_average"]
    assert load is None or (len(load) == 3 and all(x >= 0 for x in load))


def test_load_average_is_the_systems(monkeypatch):
    monkeypatch.setattr(os, "getloadavg", lambda: (1.5, 2.0, 2.5))
    assert load_average() == (1.5, 2.0, 2.5)

    def unavailable():
        raise OSError("no load average")

    monkeypatch.setattr(os, "getloadavg", unavailable)
    assert load_average() is None


def test_compile_bytecode_writes_every_modules_cache(tmp_path, monkeypatch):
    """Whole-process benchmarks start rtpy as an installed package does, from bytecode."""
    monkeypatch.setattr(sys, "pycache_prefix", str(tmp_path))  # not beside the sources
    compile_bytecode()
    package = Path(rtpy.__file__).parent
    for module in ("vec3.py", "numpy_backend/quad.py", "cli/main.py"):
        cached = Path(importlib.util.cache_from_source(str(package / module)))
        assert cached.is_relative_to(tmp_path) and cached.exists()
