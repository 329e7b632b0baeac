"""The batched sampling routines against rtpy.sampling with the same uniform numbers,
and cos_sin_2pi against cos and sin of 2 pi u evaluated in extended precision."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from rtpy import sampling as scalar
from rtpy.numpy_backend.sampling import (
    cos_sin_2pi,
    cosine_direction,
    make_generator,
    power_heuristic,
    uniform_sphere,
    unit_disk,
)

from .test_camera import Replay

# pi to 36 digits; np.longdouble carries 64 mantissa bits on x86-64 Linux.
PI_LONG = np.longdouble("3.14159265358979323846264338327950288")
EXTENDED = np.finfo(np.longdouble).nmant >= 63


def exact(u: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    angle = 2 * PI_LONG * u.astype(np.longdouble)
    return np.cos(angle), np.sin(angle)


@pytest.mark.skipif(not EXTENDED, reason="needs 80-bit long double for the reference")
def test_within_a_few_ulp_of_the_exact_values():
    u = np.random.default_rng(3).random(200_000)
    cos, sin = cos_sin_2pi(u)
    ref_cos, ref_sin = exact(u)
    # Absolute error: |cos|, |sin| <= 1, and one ulp of 1 is 2.2e-16.
    assert float(np.max(np.abs(cos - ref_cos))) < 3e-16
    assert float(np.max(np.abs(sin - ref_sin))) < 3e-16
    # numpy's own, whose argument 2 pi u is rounded first, is several times worse:
    # the bound above is not loose.
    assert float(np.max(np.abs(np.cos(2 * np.pi * u) - ref_cos))) > 4e-16


def test_quarter_turns_are_exact():
    u = np.array([0.0, 0.25, 0.5, 0.75, 1.0, -0.25])
    cos, sin = cos_sin_2pi(u)
    assert cos.tolist() == [1.0, 0.0, -1.0, 0.0, 1.0, 0.0]
    assert sin.tolist() == [0.0, 1.0, 0.0, -1.0, 0.0, -1.0]


@given(st.lists(st.floats(0.0, 1.0), min_size=1, max_size=50))
def test_agrees_with_numpy_and_stays_on_the_unit_circle(values):
    u = np.array(values)
    cos, sin = cos_sin_2pi(u)
    np.testing.assert_allclose(cos, np.cos(2 * np.pi * u), rtol=0, atol=1e-15)
    np.testing.assert_allclose(sin, np.sin(2 * np.pi * u), rtol=0, atol=1e-15)
    np.testing.assert_allclose(cos * cos + sin * sin, 1.0, rtol=0, atol=1e-15)


def test_directions_are_the_scalar_ones_from_the_same_numbers():
    """The same uniform numbers give the scalar directions: bit for bit in the unit
    disk (both call the C library's cos and sin), and within 1e-15 where an azimuth
    comes from cos_sin_2pi."""
    r = np.random.default_rng(4).random((2, 500))
    disk = np.stack(unit_disk(r[0], r[1]), axis=1)
    sphere = np.stack(uniform_sphere(r[0], r[1]), axis=1)
    cosine = np.stack(cosine_direction(r[0], r[1]), axis=1)
    for k in range(r.shape[1]):
        with scalar.use_generator(Replay(r[:, k])):
            p = scalar.random_in_unit_disk()
        assert (disk[k] == [p.e0, p.e1]).all()
        np.testing.assert_allclose(sphere[k], scalar.uniform_sphere(*r[:, k]), rtol=0, atol=1e-15)
        with scalar.use_generator(Replay(r[:, k])):
            c = scalar.random_cosine_direction()
        np.testing.assert_allclose(cosine[k], c, rtol=0, atol=1e-15)


def test_power_heuristic_matches_scalar():
    rng = np.random.default_rng(0)
    a, b = rng.exponential(size=1000), rng.exponential(size=1000)
    a[:10] = 0.0
    b[:5] = 0.0
    ref = [scalar.power_heuristic(x, y) for x, y in zip(a, b, strict=True)]
    np.testing.assert_array_equal(power_heuristic(a, b), ref)


def test_generators_depend_on_the_whole_key_only():
    a = make_generator(7, 3, 1).random(4)
    np.testing.assert_array_equal(a, make_generator(7, 3, 1).random(4))
    for other in ((7, 3, 2), (7, 4, 1), (8, 3, 1)):
        assert not np.array_equal(a, make_generator(*other).random(4))
    assert math.isclose(make_generator(np.int64(7), 3, 1).random(), a[0])


def test_unit_disk_and_cone_angle_are_the_scalar_ones_to_the_bit():
    from rtpy.numpy_backend.sampling import cone_angle, unit_disk

    rng = np.random.default_rng(7)
    r1, r2 = rng.random(200), rng.random(200)
    xs, ys = unit_disk(r1, r2)
    cos_t, sin2_t = cone_angle(r1, r2)
    for k in range(200):
        a, b = float(r1[k]), float(r2[k])
        assert scalar.disk_point(a, b) == (xs[k], ys[k])
        assert scalar.cone_angle(a, b) == (cos_t[k], sin2_t[k])
