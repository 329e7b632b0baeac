"""Hypothesis strategies shared by the tests: floats of extreme magnitude."""

from __future__ import annotations

import math
import sys

from hypothesis import strategies as st

SMALLEST = 5e-324  # the smallest subnormal float64
LARGEST = sys.float_info.max

# The ends of float64 and the values that break arithmetic: zeros of both signs, the
# smallest subnormal, the largest float, NaN and the infinities.
SPECIAL_FLOATS = (0.0, -0.0, SMALLEST, -SMALLEST, LARGEST, -LARGEST, math.nan, math.inf, -math.inf)


def _power_of_ten(exponent: float, lo: float, hi: float) -> float:
    """10^exponent kept inside [lo, hi] (the exponent's ends round either way)."""
    try:
        value = 10.0**exponent
    except OverflowError:
        value = hi
    return min(hi, max(lo, value))


def extreme_floats(
    lo: float = SMALLEST,
    hi: float = LARGEST,
    *,
    signed: bool = False,
    zero: bool = False,
    non_finite: bool = False,
) -> st.SearchStrategy[float]:
    """Floats whose magnitude is log-uniform in [lo, hi] (every decade as likely, the
    subnormals too when lo is below 2.2e-308), with lo and hi themselves drawn often;
    either sign when signed; 0.0 (and -0.0 when signed) when zero; nan and +-inf when
    non_finite. lo > 0."""
    if not 0.0 < lo <= hi:
        raise ValueError(f"need 0 < lo <= hi, got {lo}, {hi}")
    exponents = st.floats(math.log10(lo), math.log10(hi))
    magnitude = st.one_of(
        st.sampled_from([lo, hi]), exponents.map(lambda e: _power_of_ten(e, lo, hi))
    )
    values = st.tuples(magnitude, st.booleans()).map(lambda m: -m[0] if m[1] else m[0])
    values = values if signed else magnitude
    extras = ([0.0, -0.0] if signed else [0.0]) if zero else []
    if non_finite:
        extras += [math.nan, math.inf, -math.inf]
    return st.one_of(st.sampled_from(extras), values) if extras else values
