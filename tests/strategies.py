"""Hypothesis strategies shared by the tests: numbers over every magnitude float64 holds."""

from __future__ import annotations

import math

from hypothesis import strategies as st

# The ends of float64 and the values that break arithmetic: zeros of both signs, the
# smallest subnormal, the largest float, NaN and the infinities.
SPECIAL_FLOATS = (
    0.0,
    -0.0,
    5e-324,
    -5e-324,
    1.7976931348623157e308,
    -1.7976931348623157e308,
    math.nan,
    math.inf,
    -math.inf,
)


def extreme_floats() -> st.SearchStrategy[float]:
    """sign * 10**u with u uniform in [-300, 300] (each decade as likely as the next),
    or one of SPECIAL_FLOATS."""
    magnitudes = st.floats(-300.0, 300.0).map(lambda u: 10.0**u)
    signed = st.tuples(st.sampled_from((1.0, -1.0)), magnitudes).map(lambda p: p[0] * p[1])
    return st.one_of(st.sampled_from(SPECIAL_FLOATS), signed)
