"""The typed values of scene files and render settings, checked one at a time.

Each check returns the value as rtpy uses it (a float, an int, a tuple of three
floats, ...) or raises Invalid, whose detail says what was expected and what
was found in the words of a scene file ("expected an integer in [1, 1000000],
found 0"); the caller adds where (file, table and key, or the parameter name).
Booleans are not numbers, NaN and infinities are refused, and a float is not
taken for an integer.
"""

from __future__ import annotations

import difflib
import json
import math
from collections.abc import Iterable
from dataclasses import dataclass
from numbers import Integral, Real
from typing import Any

__all__ = [
    "ANY",
    "MAX_RADIANCE",
    "NON_NEGATIVE",
    "POSITIVE",
    "RADIANCE",
    "UNIT",
    "Invalid",
    "Range",
    "boolean",
    "describe",
    "integer",
    "is_number",
    "num_text",
    "number",
    "string",
    "suggest",
    "triple",
]


class Invalid(Exception):
    """A value that breaks its type or range. detail: "expected ..., found ...";
    suggestion: the nearest valid name for a misspelt one; wrong_type: the value
    has the wrong type (as opposed to a value out of range)."""

    def __init__(self, detail: str, suggestion: str | None = None, wrong_type: bool = False):
        super().__init__(detail)
        self.detail = detail
        self.suggestion = suggestion
        self.wrong_type = wrong_type


def suggest(word: str, choices: Iterable[str]) -> str | None:
    """The valid name closest to a misspelt one, if any is close."""
    matches = difflib.get_close_matches(word, list(choices), n=1, cutoff=0.6)
    return matches[0] if matches else None


# --- describing values -----------------------------------------------------------------------


def is_number(v: Any) -> bool:
    return isinstance(v, Real) and not isinstance(v, bool)


def num_text(v: int | float) -> str:
    """A number as a message shows it: integers whole, huge ones named, floats short."""
    if isinstance(v, Integral):
        v = int(v)
        return str(v) if v.bit_length() <= 64 else "a very large integer"
    v = float(v)
    if math.isnan(v):
        return "nan"
    if math.isinf(v):
        return "inf" if v > 0 else "-inf"
    return str(int(v)) if v.is_integer() and abs(v) < 1e15 else repr(v)


def _short(text: str, limit: int = 60) -> str:
    return text if len(text) <= limit else text[: limit - 3] + "..."


def describe(v: Any) -> str:
    """What was found, for messages."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, Integral):
        return num_text(v)
    if isinstance(v, Real):
        return num_text(v) if not float(v).is_integer() else repr(float(v))
    if isinstance(v, str):
        return "the string " + _short(json.dumps(v, ensure_ascii=False))
    if isinstance(v, list | tuple):
        if len(v) <= 4 and all(isinstance(x, Real) for x in v):
            return "[" + ", ".join(describe(x) for x in v) + "]"
        return f"an array of {len(v)} item{'s' if len(v) != 1 else ''}"
    if isinstance(v, dict):
        return "a table"
    return f"a {type(v).__name__}"  # dates and times, objects


def _expected(what: str, found: Any, wrong_type: bool = False) -> Invalid:
    return Invalid(f"expected {what}, found {describe(found)}", wrong_type=wrong_type)


# --- ranges ----------------------------------------------------------------------------------


@dataclass(frozen=True)
class Range:
    """An interval of allowed numbers, each end closed, open or absent."""

    lo: float | None = None
    hi: float | None = None
    lo_open: bool = False
    hi_open: bool = False

    def __contains__(self, x: float) -> bool:
        if self.lo is not None and (x <= self.lo if self.lo_open else x < self.lo):
            return False
        return not (self.hi is not None and (x >= self.hi if self.hi_open else x > self.hi))

    def text(self) -> str:
        lo = None if self.lo is None else num_text(self.lo)
        hi = None if self.hi is None else num_text(self.hi)
        if lo is not None and hi is not None:
            return f"in {'(' if self.lo_open else '['}{lo}, {hi}{')' if self.hi_open else ']'}"
        if lo is not None:
            return f"{'>' if self.lo_open else '>='} {lo}"
        if hi is not None:
            return f"{'<' if self.hi_open else '<='} {hi}"
        return ""


ANY = Range()
POSITIVE = Range(0, None, lo_open=True)
NON_NEGATIVE = Range(0)
# Radiance (emit, intensity, background) and the kd / ks weights are bounded so that
# no sum of samples can overflow: a path's weight grows at most about 2x a bounce
# with kd, ks <= 1, so even 10^6 samples of 500 bounces stay below 1e30 * 1e157.
MAX_RADIANCE = 1e30
RADIANCE = Range(0, MAX_RADIANCE)
UNIT = Range(0, 1)


# --- the checks ------------------------------------------------------------------------------


def number(v: Any, rng: Range = ANY) -> float:
    """A finite number in rng (an integer is a number too)."""
    what = f"a number {rng.text()}".rstrip()
    if not is_number(v):
        raise _expected(what, v, wrong_type=True)
    try:
        x = float(v)
    except OverflowError:
        x = math.inf
    if not math.isfinite(x):
        raise _expected(f"a finite number {rng.text()}".rstrip(), v)
    if x not in rng:
        raise _expected(what, v)
    return x


def integer(v: Any, rng: Range = ANY, limit: str = "") -> int:
    """An integer in rng; limit says why the range ends (" (larger ... are refused)")."""
    what = f"an integer {rng.text()}".rstrip() + limit
    if isinstance(v, Real) and not isinstance(v, Integral | bool):
        x = float(v)
        if math.isfinite(x) and x.is_integer():
            raise Invalid(
                f"expected {what}, found {x!r} (write {int(x)} without the decimal point)",
                wrong_type=True,
            )
    if not isinstance(v, Integral) or isinstance(v, bool):
        raise _expected(what, v, wrong_type=True)
    if v not in rng:
        raise _expected(what, v)
    return int(v)


def boolean(v: Any) -> bool:
    if not isinstance(v, bool):
        raise _expected("true or false", v, wrong_type=True)
    return v


def string(v: Any, choices: tuple[str, ...] = ()) -> str:
    """A string, one of choices when they are given (with the nearest as a suggestion)."""
    listed = ", ".join(f'"{c}"' for c in choices)
    what = f"one of {listed}" if choices else "a string"
    if not isinstance(v, str):
        raise _expected(what, v, wrong_type=True)
    if choices and v not in choices:
        raise Invalid(f"expected {what}, found {describe(v)}", suggest(v, choices))
    return v


def triple(v: Any, rng: Range = ANY) -> tuple[float, float, float]:
    """An array of 3 finite numbers, each in rng (a position, a direction, a colour)."""
    each = f", each {rng.text()}" if rng.text() else ""
    what = f"an array of 3 finite numbers{each}"
    if not isinstance(v, list | tuple) or len(v) != 3:
        raise _expected(what, v, wrong_type=True)
    out = []
    for i, x in enumerate(v):
        if not is_number(x):
            why = " (booleans are not numbers)" if isinstance(x, bool) else ""
            raise Invalid(
                f"expected {what}, found {describe(x)} as component {i + 1}{why}", wrong_type=True
            )
        try:
            f = float(x)
        except OverflowError:
            f = math.inf
        if not math.isfinite(f) or f not in rng:
            raise Invalid(
                f"expected {what}, found {describe(v)} (component {i + 1} is {describe(x)})"
            )
        out.append(f)
    return (out[0], out[1], out[2])
