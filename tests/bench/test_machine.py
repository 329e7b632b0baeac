"""rtpy.bench.machine: what a benchmark's timings depend on besides the code."""

from __future__ import annotations

import os
import platform

import numpy as np

from rtpy.bench.machine import cpu_model, load_average, machine


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
