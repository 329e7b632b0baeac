"""cos_sin_2pi against cos and sin of 2 pi u evaluated in extended precision."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from rtpy.numpy_backend.trig import cos_sin_2pi

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
