"""Tests for rtpy.interval: closed vs open membership, clamp, empty and universe."""

from __future__ import annotations

import math

from hypothesis import given, settings
from hypothesis import strategies as st

from rtpy.interval import Interval


def test_contains_includes_endpoints_surrounds_excludes_them():
    iv = Interval(1.0, 2.0)
    assert iv.contains(1.0) and iv.contains(2.0) and iv.contains(1.5)
    assert not iv.surrounds(1.0) and not iv.surrounds(2.0)
    assert iv.surrounds(1.5)
    assert not iv.contains(math.nextafter(1.0, 0.0))
    assert not iv.contains(math.nextafter(2.0, 3.0))
    assert iv.surrounds(math.nextafter(1.0, 2.0))
    assert iv.surrounds(math.nextafter(2.0, 1.0))


def test_degenerate_point_interval():
    iv = Interval(3.0, 3.0)
    assert iv.contains(3.0)
    assert not iv.surrounds(3.0)
    assert iv.size() == 0.0
    assert not iv.is_empty()


def test_size():
    assert Interval(-1.5, 2.0).size() == 3.5
    assert Interval(0.0, math.inf).size() == math.inf


def test_clamp():
    iv = Interval(0.0, 1.0)
    assert iv.clamp(-0.5) == 0.0
    assert iv.clamp(1.5) == 1.0
    assert iv.clamp(0.25) == 0.25
    assert iv.clamp(0.0) == 0.0
    assert iv.clamp(1.0) == 1.0
    assert iv.clamp(-math.inf) == 0.0
    assert iv.clamp(math.inf) == 1.0


@settings(deadline=None, max_examples=60)
@given(st.floats(-1e6, 1e6), st.floats(0.0, 1e6), st.floats(allow_nan=False, allow_infinity=True))
def test_clamp_lands_inside_and_is_identity_inside(lo, width, x):
    iv = Interval(lo, lo + width)
    c = iv.clamp(x)
    assert iv.contains(c)
    if iv.contains(x):
        assert c == x
    else:
        assert c == (iv.min if x < iv.min else iv.max)


def test_empty():
    for iv in (Interval(), Interval.empty()):
        assert iv.is_empty()
        assert iv.size() == -math.inf
        for x in (0.0, 1e300, -1e300, math.inf, -math.inf):
            assert not iv.contains(x)
            assert not iv.surrounds(x)


def test_universe():
    iv = Interval.universe()
    assert not iv.is_empty()
    assert iv.size() == math.inf
    for x in (0.0, 1e300, -1e300):
        assert iv.contains(x) and iv.surrounds(x)
    # Infinity is an endpoint: contained but not surrounded.
    assert iv.contains(math.inf) and not iv.surrounds(math.inf)


def test_reversed_interval_is_empty():
    iv = Interval(2.0, 1.0)
    assert iv.is_empty()
    assert not iv.contains(1.5)
