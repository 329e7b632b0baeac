"""Same seed, same settings: the same image bit for bit, across runs, processes
and worker counts, on each backend.

Each render draws from generators seeded by (seed, tile, batch), and finished
units are added tile by tile in batch order, whatever order the workers finish
them in. What the naive renderer gets wrong: one generator shared by the whole
image (or by each worker) makes the image depend on which worker took which
tile, and adding unit sums as they arrive makes the rounding depend on it; a
set or a dict keyed by id() iterated while building the scene makes it depend
on PYTHONHASHSEED or on memory addresses, which differ between runs. The
subprocess test runs the CLI with another hash seed.
"""

from __future__ import annotations

import os
import subprocess

import numpy as np
import pytest

import rtpy

from ..commands import rtpy_command

CASES = [
    ("cornell", {"integrator": "path", "spp": 2, "max_depth": 6}),
    ("week08_three_balls", {"integrator": "whitted", "spp": 2, "max_depth": 5}),
    ("material_gallery", {"integrator": "direct", "spp": 2, "nee": True}),
    ("week07_textures", {"integrator": "path", "spp": 2, "nee": False, "russian_roulette": 1}),
]
# Several tiles and several sample batches per tile on each backend (scalar: 16x16
# tiles, a batch per sample; numpy: 32x32 tiles, 16 samples a batch).
WIDTH = {"scalar": 20, "numpy": 40}
SPP_FACTOR = {"scalar": 1, "numpy": 9}


def render_kw(backend: str, settings: dict) -> dict:
    spp = settings["spp"] * SPP_FACTOR[backend]
    return {"width": WIDTH[backend], "seed": 12345, "backend": backend, **settings, "spp": spp}


@pytest.mark.parametrize("backend", rtpy.BACKENDS)
@pytest.mark.parametrize("name,settings", CASES, ids=[c[0] for c in CASES])
def test_same_seed_same_image_for_1_and_2_workers(backend, name, settings):
    scene = rtpy.load_scene(name)
    kw = render_kw(backend, settings)
    one = rtpy.render(scene, workers=1, **kw).linear
    two = rtpy.render(rtpy.load_scene(name), workers=2, **kw).linear
    assert np.isfinite(one).all() and one.max() > 0
    np.testing.assert_array_equal(one, two)
    if name == "cornell":  # the seed matters: the check can fail
        other_seed = rtpy.render(scene, workers=1, **{**kw, "seed": 54321}).linear
        assert not np.array_equal(one, other_seed)


@pytest.mark.parametrize("backend", rtpy.BACKENDS)
def test_same_image_in_another_process_with_another_hash_seed(tmp_path, backend):
    name, settings = CASES[0]
    out = tmp_path / "run.npy"
    env = {**os.environ, "PYTHONHASHSEED": "4242"}
    argv = rtpy_command("render", name, "--backend", backend)
    kw = render_kw(backend, settings)
    argv += ["--width", str(kw["width"]), "--seed", "12345", "--workers", "2", "--quiet"]
    argv += [f"--set={k}={str(v).lower()}" for k, v in kw.items() if k in ("spp", "max_depth")]
    argv += ["--integrator", settings["integrator"], "-o", str(tmp_path / "run.png")]
    result = subprocess.run(
        [*argv, "--linear", str(out)], env=env, capture_output=True, text=True, timeout=120
    )
    assert result.returncode == 0, result.stderr
    here = rtpy.render(rtpy.load_scene(name), **kw).linear
    np.testing.assert_array_equal(np.load(out), here)
