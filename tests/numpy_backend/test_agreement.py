"""The numpy backend renders the scalar backend's images, up to Monte Carlo noise.

For every bundled scene and integrator, each backend renders the scene R times
with different seeds (small images, moderate spp; the numpy backend, being cheap,
with NUMPY_FACTOR times the spp). The images are cut into 8 x 8 blocks and the
mean of each block compared by a z-test against the noise the renders measure:

- a pixel's per-sample variance s2 is estimated from the spread of its R values
  (variance across renders times spp), pooled over both backends, which under
  the hypothesis being tested (the same estimator) have the same s2. Pooling
  keeps a rare bright sample (a firefly) that one backend happened to draw
  equally often in every render from hiding the noise;
- the mean over R renders of a block of n pixels then has variance
  sum(s2) / (spp R n^2) per backend;
- a block differs significantly when |mean_numpy - mean_scalar| over the square
  root of the summed variances exceeds the normal quantile of a two-sided test at
  level ALPHA / (blocks x channels) (Bonferroni): the chance that any block of a
  correct backend is flagged is below ALPHA. The seeds are fixed, so the test is
  deterministic.

The "center" integrator draws no random numbers without a lens: its images must
be equal. test_a_biased_kernel_is_flagged shows that the comparison has the power
to catch a real mistake (light counted twice by a wrong MIS weight).
"""

from __future__ import annotations

from functools import cache

import numpy as np
import pytest

import rtpy
from rtpy.io.bundled import bundled_scenes
from rtpy.numpy_backend.integrators import direct_lighting
from rtpy.testing.statistics import BlockTest, block_z_test

from ..cores import on_every_core
from ..tiers import slow_except

ALPHA = 1e-3
WIDTH = 32
SCENES = [name for name, _ in bundled_scenes()]
# Scalar spp per integrator (the numpy backend uses NUMPY_FACTOR times more: it is cheap).
SPP = {"jittered": 2, "shading": 2, "direct": 3, "whitted": 2, "path": 3}
NUMPY_FACTOR = 4
SEEDS = (11, 12, 13, 14)
BACKENDS = ("scalar", "numpy")


def render(job: tuple[str, str, str, int, int]) -> np.ndarray:
    """The linear image of a bundled scene, WIDTH pixels wide, for the job (name,
    integrator, backend, seed, spp), in this process (a seed gives the same image on
    any number of workers)."""
    name, integrator, backend, seed, spp = job
    settings = {"width": WIDTH, "spp": spp, "integrator": integrator, "seed": seed}
    return rtpy.render(rtpy.load_scene(name), backend=backend, **settings).linear


def compare(renders_a, spp_a, renders_b, spp_b, alpha: float = ALPHA) -> BlockTest:
    """block_z_test of two stacks of R independent renders (R, H, W, 3) at spp_a and
    spp_b, each pixel's per-sample variance pooled over both backends."""
    a, b = np.asarray(renders_a), np.asarray(renders_b)
    s2 = 0.5 * (a.var(axis=0, ddof=1) * spp_a + b.var(axis=0, ddof=1) * spp_b)
    var_a, var_b = s2 / (spp_a * len(a)), s2 / (spp_b * len(b))
    return block_z_test(a.mean(axis=0), var_a, b.mean(axis=0), var_b, alpha)


def renders_uncached(name: str, integrator: str, backend: str, spp: int) -> list[np.ndarray]:
    """The renders with every seed of SEEDS, on every core."""
    return on_every_core(render, [(name, integrator, backend, s, spp) for s in SEEDS])


renders = cache(renders_uncached)


def check(name: str, integrator: str, spp: int) -> None:
    numpy_spp = spp * NUMPY_FACTOR
    test = compare(
        renders(name, integrator, "scalar", spp),
        spp,
        renders(name, integrator, "numpy", numpy_spp),
        numpy_spp,
    )
    assert test.passed, "scalar backend: " + test.worst("the numpy backend")


@pytest.mark.parametrize("name", slow_except(SCENES, "cornell"))
def test_center_images_agree(name):
    if rtpy.load_scene(name).camera.defocus_angle > 0:
        check(name, "center", 1)  # the lens is sampled: compare as noise
        return
    a, b = on_every_core(render, [(name, "center", backend, 0, 1) for backend in BACKENDS])
    # A pixel centre on the exact edge of a quad may round to either side.
    close = np.isclose(a, b, rtol=1e-9, atol=1e-12).all(axis=2)
    assert close.mean() > 0.99, f"{(~close).sum()} pixels differ"


CASES = [(name, integrator) for name in SCENES for integrator in SPP]


@pytest.mark.parametrize("name,integrator", slow_except(CASES, ("cornell", "path")))
def test_block_means_agree(name, integrator):
    check(name, integrator, SPP[integrator])


def test_a_biased_kernel_is_flagged(monkeypatch):
    """Counting light twice (emission found by BRDF sampling kept at weight 1 while
    lights are also sampled) brightens every lit block: the comparison flags it."""
    name, integrator, spp = "cornell", "path", SPP["path"]
    scalar = renders(name, integrator, "scalar", spp)
    monkeypatch.setattr(direct_lighting, "emission_weight", lambda _, obj, *a: np.ones(len(obj)))
    biased = renders_uncached(name, integrator, "numpy", spp * NUMPY_FACTOR)  # forked: patched
    test = compare(scalar, spp, biased, spp * NUMPY_FACTOR)
    assert not test.passed
    assert (test.z > test.threshold).any(axis=1).sum() > 1  # many blocks, not one
