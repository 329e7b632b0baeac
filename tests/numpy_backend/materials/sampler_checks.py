"""The batched samplers against the scalar ones fed the same uniform numbers: the
kernels' scattering() with the scalar local samplers swapped in, and the bounds the
local samplers themselves keep. Used by the tests in this folder.
"""

from __future__ import annotations

import numpy as np

from rtpy.materials import CookTorrance, Ward
from rtpy.materials import phong as scalar_phong
from rtpy.numpy_backend.hit_info import HitBatch
from rtpy.numpy_backend.materials import (
    MaterialTable,
    blinn_phong,
    glossy,
    lambertian,
    oren_nayar,
    phong,
)
from rtpy.numpy_backend.materials.cook_torrance import CookTorranceKernel, GGXKernel
from rtpy.numpy_backend.materials.ward import WardKernel
from rtpy.sampling import random_cosine_direction, use_generator

from ..test_camera import Replay
from .kernel_checks import LIBM_REL, assert_agrees, scalar_dot, scalar_hit

# The lobe samplers' local directions against the scalar samplers': their pow, log1p and
# arctan2 differ by at most LIBM_ULPS ulp of the result (1 measured here; numpy's own
# accuracy tests allow a few), and cos_sin_2pi(u) from the scalar code's
# math.cos(2 * math.pi * u) and math.sin by at most AZIMUTH: it is within 3e-16 of the
# exact values (tests/numpy_backend/test_sampling.py), while math's rounding of pi adds up
# to 2.5e-16 over [0, 2 pi), of 2 pi u 4.4e-16, and of its result 2.2e-16.
LIBM_ULPS = 4
AZIMUTH = 1.2e-15


class Recorder:
    """A numpy Generator's random(shape) that keeps what it returned, in `draws`."""

    def __init__(self, rng: np.random.Generator) -> None:
        self.rng, self.draws = rng, []

    def random(self, shape) -> np.ndarray:
        r = self.rng.random(shape)
        self.draws.append(r)
        return r


def _per_element(sample, *args: np.ndarray):
    """Columns of the scalar Vec3s sample(*one element of each arg)."""
    values = [tuple(sample(*a)) for a in zip(*(x.tolist() for x in args), strict=True)]
    out = np.array(values, dtype=np.float64).reshape(-1, 3)
    return out[:, 0], out[:, 1], out[:, 2]


def _scalar_cosine_direction(r1: np.ndarray, r2: np.ndarray):
    def one(a, b):
        with use_generator(Replay([a, b])):
            return random_cosine_direction()

    return _per_element(one, r1, r2)


def use_scalar_local_samplers(monkeypatch) -> None:
    """Replace the batched local samplers (cosine_direction, sample_cosine_power and the
    half-vector samplers of Cook-Torrance and Ward) by the scalar ones, element by
    element. They differ only where numpy's cos_sin_2pi, pow, log1p and arctan2 round
    differently from the C library's (tested on their own); with the scalar ones, the
    world-space steps of scattering() (frames, reflections, the lobe's choice,
    absorption) must give the scalar directions bit for bit."""
    for module in (glossy, lambertian, oren_nayar):
        monkeypatch.setattr(module, "cosine_direction", _scalar_cosine_direction)

    def cosine_power(exponent, r1, r2):
        return _per_element(scalar_phong.sample_cosine_power, exponent, r1, r2)

    for module in (phong, blinn_phong):
        monkeypatch.setattr(module, "sample_cosine_power", cosine_power)

    def facet(kernel, alpha, r1, r2):
        distribution = "ggx" if isinstance(kernel, GGXKernel) else "beckmann"
        return _per_element(
            lambda a, u, v: CookTorrance(roughness=a, distribution=distribution).sample_half_vector(
                u, v
            ),
            alpha,
            r1,
            r2,
        )

    def ward(kernel, ax, ay, r1, r2):
        return _per_element(
            lambda x, y, u, v: Ward(alpha_x=x, alpha_y=y).sample_half_vector(u, v), ax, ay, r1, r2
        )

    monkeypatch.setattr(CookTorranceKernel, "sample_half_vector", facet)
    monkeypatch.setattr(WardKernel, "sample_half_vector", ward)


def check_scattering_equals_scalar(table: MaterialTable, ids, hits: HitBatch, rng) -> None:
    """Each kernel's scattering() against the scalar scattering() fed the same uniform
    numbers, hit by hit: absorbed alike, the same direction bit for bit, pdf and weight
    to LIBM_REL. Call after use_scalar_local_samplers. A kernel draws its numbers for
    every hit (Lambertian) or for the hits whose viewer lies above the surface, as
    columns of one rng.random((k, m)) call, k the numbers a scalar sample draws."""
    for kind, kernel in enumerate(table.kernels):
        rows = np.flatnonzero(table.kind[ids] == kind)
        if len(rows) == 0:
            continue
        part, recorder = hits.take(rows), Recorder(rng)
        s = kernel.scattering(table.slot[ids[rows]], part, recorder)
        (numbers,) = recorder.draws
        drew = np.arange(len(rows))
        if numbers.shape[1] != len(rows):
            drew = np.flatnonzero(scalar_dot(part.normal, part.wo) > 0.0)
        assert numbers.shape[1] == len(drew), "the numbers drawn do not match the hits"
        column = dict(zip(drew.tolist(), range(len(drew)), strict=True))
        for i, row in enumerate(rows.tolist()):
            m, hit, ray_in = scalar_hit(table.materials, ids, hits, row)
            k = column.get(i)
            with use_generator(Replay(numbers[:, k] if k is not None else [0.5] * 3)):
                expected = m.scattering(ray_in, hit)
            assert s.alive[i] == (expected is not None), f"absorbed at {row}: {expected}"
            if expected is None:
                continue
            direction = s.direction[i].tolist()
            assert direction == list(expected.scattered_ray.direction), f"direction at {row}"
            assert_agrees(s.pdf[i], expected.pdf, f"pdf at {row}", LIBM_REL)
            assert_agrees(
                s.attenuation[i], tuple(expected.attenuation), f"weight at {row}", LIBM_REL
            )
