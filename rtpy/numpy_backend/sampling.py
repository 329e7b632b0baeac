"""Random numbers and the sampling routines built on them: the batched rtpy.sampling.

The backend never draws from a global generator: every unit of work gets its own
numpy Generator from make_generator(seed, tile, batch), and every routine that needs
randomness is passed that generator (or the uniform numbers drawn from it). The
routines map uniform numbers in [0, 1) to directions exactly as their scalar twins
do, so the same numbers give the same directions; azimuths are the exception (see
cos_sin_2pi).

cos_sin_2pi(u) gives cos(2 pi u) and sin(2 pi u) without numpy's cos and sin, which
call the C library once per element and cost as much as dozens of multiplications:

- 4u = q + f with q = rint(4u) and f in [-1/2, 1/2], both exact in floating point,
  so 2 pi u = q pi/2 + x with x = f pi/2 in [-pi/4, pi/4];
- sin x and cos x by their Taylor series to x^15 and x^16 (the first terms left out
  are below 5e-17 on that interval);
- a quarter turn q (mod 4) rotates (cos x, sin x) exactly: multiplying by 0 or +-1
  and adding 0 does not round.

The result is within 2.1e-16 of the exact value (tests/numpy_backend/test_sampling.py),
closer than np.cos(2 * np.pi * u), whose argument is rounded first, and within a
few 1e-16 of the scalar code's math.cos(2 * math.pi * u).
"""

from __future__ import annotations

import math

import numpy as np

from .onb import local_to_world
from .vec3 import Columns

HALF_PI = 0.5 * math.pi
# Taylor coefficients in x^2, highest power first: sin x = x * S(x^2), cos x = C(x^2).
_SIN = [(-1) ** k / math.factorial(2 * k + 1) for k in range(7, -1, -1)]
_COS = [(-1) ** k / math.factorial(2 * k) for k in range(8, -1, -1)]
# cos and sin of q quarter turns, q = 0, 1, 2, 3.
_COS_Q = np.array([1.0, 0.0, -1.0, 0.0])
_SIN_Q = np.array([0.0, 1.0, 0.0, -1.0])


def make_generator(*key: int) -> np.random.Generator:
    """A numpy Generator seeded from a tuple of integers (stable across processes
    and runs): the twin of rtpy.sampling.make_generator."""
    return np.random.default_rng([int(k) for k in key])


def _series(coefficients: list[float], x2: np.ndarray) -> np.ndarray:
    """Horner's rule for sum_k c_k x2^k, coefficients highest power first."""
    out = x2 * coefficients[0]
    out += coefficients[1]
    for c in coefficients[2:]:
        out *= x2
        out += c
    return out


def cos_sin_2pi(u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(cos(2 pi u), sin(2 pi u)) for an array u of numbers of moderate size
    (|u| < 2^50; sampling passes [0, 1))."""
    v = 4.0 * np.asarray(u, dtype=np.float64)
    q = np.rint(v)
    x = v - q
    x *= HALF_PI
    x2 = x * x
    sin_x = _series(_SIN, x2)
    sin_x *= x
    cos_x = _series(_COS, x2)
    quarter = q.astype(np.intp)
    quarter &= 3
    cq, sq = _COS_Q.take(quarter), _SIN_Q.take(quarter)
    cos = cq * cos_x
    cos -= sq * sin_x
    sin = sq * cos_x
    sin += cq * sin_x
    return cos, sin


def uniform_sphere(r1: np.ndarray, r2: np.ndarray) -> Columns:
    """rtpy.sampling.uniform_sphere: points uniform on the unit sphere."""
    # Twin kept: the azimuth comes from cos_sin_2pi, not the C library's cos and sin.
    z = 1.0 - 2.0 * r1
    s = np.sqrt(np.maximum(0.0, 1.0 - z * z))
    cos_phi, sin_phi = cos_sin_2pi(r2)
    return s * cos_phi, s * sin_phi, z


def cosine_direction(r1: np.ndarray, r2: np.ndarray) -> Columns:
    """rtpy.sampling.random_cosine_direction from its two uniform numbers: local
    (x, y, z) in the z-up hemisphere with pdf cos(theta) / pi."""
    # Twin kept: the azimuth comes from cos_sin_2pi, not the C library's cos and sin.
    cos_phi, sin_phi = cos_sin_2pi(r1)
    s = np.sqrt(r2)
    return s * cos_phi, s * sin_phi, np.sqrt(np.maximum(0.0, 1.0 - r2))


def unit_disk(r1: np.ndarray, r2: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """rtpy.sampling.random_in_unit_disk from its two uniform numbers: (x, y) uniform
    in the unit disk, as rtpy.sampling.disk_point computes them (numpy's cos and sin
    call the same C library as math's)."""
    radius = np.sqrt(r1)
    phi = 2.0 * math.pi * r2
    return radius * np.cos(phi), radius * np.sin(phi)


def cone_angle(r1: np.ndarray, cone_size: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """rtpy.sampling.cone_angle on arrays: (cos theta, sin^2 theta)."""
    cos_t = 1.0 - r1 * cone_size
    return cos_t, np.maximum(0.0, 1.0 - cos_t * cos_t)


def cone_direction(
    axis: Columns, omc: np.ndarray, r1: np.ndarray, r2: np.ndarray
) -> tuple[Columns, np.ndarray, np.ndarray]:
    """Directions uniform by solid angle inside cones (Sphere.sample_direction seen
    from outside): (world direction, cos_t, sin_t^2) at angle cos_t = 1 - r1 omc from
    the unit axis, azimuth 2 pi r2 in the frame ONB(axis); omc is 1 - cos of the
    cone's half-angle, and the density 1 / (2 pi omc)."""
    cos_t, sin2_t = cone_angle(r1, omc)
    sin_t = np.sqrt(sin2_t)
    cos_phi, sin_phi = cos_sin_2pi(r2)
    return local_to_world(axis, sin_t * cos_phi, sin_t * sin_phi, cos_t), cos_t, sin2_t


def power_heuristic(pdf_a: np.ndarray, pdf_b: np.ndarray) -> np.ndarray:
    """rtpy.sampling.power_heuristic: Veach's power heuristic (beta = 2), 0 where
    both densities vanish."""
    # Twin kept: the zero case is the scalar's branch, the rest one line.
    a2 = pdf_a * pdf_a
    total = a2 + pdf_b * pdf_b
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(total > 0.0, a2 / total, 0.0)
