"""The typed values of scene files and render settings, checked one at a time.

Each check returns the value as rtpy uses it (a float, an int, a tuple of three
floats, ...) or raises Invalid, whose detail says what was expected and what
was found in the words of a scene file ("expected an integer in [1, 1000000],
found 0"); the caller adds where (file, table and key, or the parameter name).
Booleans are not numbers, NaN and infinities are refused, and a float is not
taken for an integer.

The ranges of the scene-file contract are named here once (COORDINATE, LENGTH,
RADIANCE, ...); the scene loader and the constructors of the Python API check
against the same ones. The Python API's checks (checked_number, checked_point,
checked_color, ...) raise TypeError for a value of the wrong type and ValueError for
one out of range, both naming the parameter.
"""

from __future__ import annotations

import difflib
import functools
import json
import math
from collections.abc import Callable, Iterable
from dataclasses import dataclass
from numbers import Integral, Real
from typing import Any

from .vec3 import Color, Vec3

__all__ = [
    "ANGLE",
    "ANY",
    "ASPECT_RATIO",
    "COORDINATE",
    "DEFOCUS_ANGLE",
    "EXPONENT",
    "FUZZ",
    "GAMMA",
    "IOR",
    "LENGTH",
    "MAX_COORDINATE",
    "MAX_LENGTH",
    "MAX_RADIANCE",
    "MIN_AREA",
    "MIN_LENGTH",
    "MIN_SINE",
    "NON_NEGATIVE",
    "POSITIVE",
    "RADIANCE",
    "ROUGHNESS",
    "SEED",
    "SIGMA",
    "UNIT",
    "VFOV",
    "Invalid",
    "Range",
    "angles",
    "boolean",
    "checked",
    "checked_color",
    "checked_edge",
    "checked_material",
    "checked_number",
    "checked_point",
    "checked_scales",
    "checked_vector",
    "components",
    "describe",
    "edge",
    "integer",
    "is_number",
    "num_text",
    "one_line",
    "number",
    "point",
    "scales",
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


def one_line(text: str) -> str:
    """text as one line of a message: line breaks, tabs and other characters that do
    not print written as Python escapes them ("a\\nb"), the rest as it is."""
    if text.isprintable():
        return text
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)


def suggest(word: str, choices: Iterable[str]) -> str | None:
    """The valid name closest to a misspelt one, if any is close."""
    matches = difflib.get_close_matches(word, list(choices), n=1, cutoff=0.6)
    return matches[0] if matches else None


# --- describing values -----------------------------------------------------------------------


def is_number(v: Any) -> bool:
    kind = type(v)
    if kind is float or kind is int:  # the common case, without the abstract class
        return True
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
        if x != x:  # NaN lies in no range
            return False
        if self.lo is not None and (x <= self.lo if self.lo_open else x < self.lo):
            return False
        return not (self.hi is not None and (x >= self.hi if self.hi_open else x > self.hi))

    @functools.cache  # noqa: B019 (ranges are few and live as long as the program)
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
UNIT = Range(0, 1)  # reflectances: albedo, kd, ks, f0, tint

# The contract's ranges. Inside them no product a render forms overflows float64 and
# the linear image fits float32 (EXR), with margin: a scene spans at most about 1e6
# units and resolves about 1e-6, and radiance stays below 1e9.
MAX_COORDINATE = 1e6
MIN_LENGTH, MAX_LENGTH = 1e-6, 1e6
COORDINATE = Range(-MAX_COORDINATE, MAX_COORDINATE)  # each component of a point
LENGTH = Range(MIN_LENGTH, MAX_LENGTH)  # radii, edges, distances, scales
# A quad with |u x v| below this, or a triangle with twice its area below it, is
# degenerate; and a camera's vup must make at least this sine with the view.
MIN_AREA = 1e-12
MIN_SINE = 1e-6
MAX_RADIANCE = 1e9
RADIANCE = Range(0, MAX_RADIANCE)  # emit, background, point-light intensity
VFOV = Range(1e-3, 179)  # degrees
DEFOCUS_ANGLE = Range(0, 179)  # degrees
ASPECT_RATIO = Range(1e-6, 1e6)
ANGLE = Range(-360, 360)  # a mesh's rotation about each axis, degrees
EXPONENT = Range(0, 1e6)  # Phong and Blinn-Phong
ROUGHNESS = Range(1e-4, 1)  # roughness, alpha_x, alpha_y
IOR = Range(1e-2, 100)
FUZZ = Range(0, 1e6)
SIGMA = Range(0, 90, hi_open=True)  # Oren-Nayar, degrees: tan(sigma) at 90 is infinite
GAMMA = Range(0, 100, lo_open=True)
SEED = Range(0, 2**63 - 1)


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


def point(v: Any) -> tuple[float, float, float]:
    """A point: 3 numbers, each in COORDINATE."""
    return triple(v, COORDINATE)


def edge(v: Any) -> tuple[float, float, float]:
    """A vector whose length lies in LENGTH (a quad's edge, a camera's vup), each
    component in COORDINATE."""
    x, y, z = triple(v, COORDINATE)
    length = math.sqrt(x * x + y * y + z * z)
    if length not in LENGTH:
        raise Invalid(
            f"expected a vector of length {LENGTH.text()}, found {describe(v)} "
            f"(length {num_text(length)})"
        )
    return (x, y, z)


def angles(v: Any) -> tuple[float, float, float]:
    """Rotation angles about x, y, z in degrees, each in ANGLE."""
    return triple(v, ANGLE)


def scales(v: Any) -> tuple[float, float, float]:
    """Scale factors along x, y, z: each of size in LENGTH (a negative one mirrors)."""
    sizes = Range(-MAX_LENGTH, MAX_LENGTH)
    x, y, z = triple(v, sizes)
    for i, s in enumerate((x, y, z)):
        if abs(s) < MIN_LENGTH:
            raise Invalid(
                f"expected 3 numbers, each in {sizes.text()[3:]} and of size >= "
                f"{num_text(MIN_LENGTH)}, found {describe(v)} (component {i + 1} is {describe(s)})"
            )
    return (x, y, z)


# --- the Python API's checks -------------------------------------------------------------------


def checked(name: str, check: Callable[..., Any], v: Any, *args: Any) -> Any:
    """check(v, *args) for a parameter of the Python API: its Invalid as a TypeError
    (wrong type) or ValueError (out of range) that names the parameter."""
    try:
        return check(v, *args)
    except Invalid as e:
        error = TypeError if e.wrong_type else ValueError
        raise error(f"{name}: {e.detail}") from None


def checked_number(name: str, v: Any, rng: Range = ANY) -> float:
    """A finite number in rng, as a float."""
    return checked(name, number, v, rng)


def components(v: Any) -> Any:
    """What triple checks: a Vec3 or a numpy array of shape (3,) as a list of its
    components; anything else as it is."""
    if isinstance(v, Vec3) or (hasattr(v, "tolist") and getattr(v, "ndim", None) == 1):
        return list(v.tolist())
    return v


def _checked_as(cls: type, name: str, check: Callable[..., Any], v: Any, *args: Any) -> Any:
    """v itself when it is a cls already, else a new cls of its three numbers; either
    after check(its components, *args) (TypeError or ValueError naming the parameter)."""
    xyz = checked(name, check, components(v), *args)
    return v if type(v) is cls else cls(*xyz)


def checked_vector(name: str, v: Any, rng: Range = ANY) -> Vec3:
    """A Vec3 from a Vec3 or 3 numbers (a tuple, a list, a numpy array), each in rng."""
    return _checked_as(Vec3, name, triple, v, rng)


def checked_point(name: str, v: Any) -> Vec3:
    """A point whose components lie in COORDINATE."""
    return _checked_as(Vec3, name, point, v)


def checked_edge(name: str, v: Any) -> Vec3:
    """A vector whose length lies in LENGTH (see edge)."""
    return _checked_as(Vec3, name, edge, v)


def checked_scales(name: str, v: Any) -> Vec3:
    """Scale factors along x, y, z (see scales)."""
    return _checked_as(Vec3, name, scales, v)


def checked_color(name: str, v: Any, rng: Range = UNIT) -> Color:
    """A Color from a Color or 3 numbers, each in rng (UNIT for reflectances)."""
    return _checked_as(Color, name, triple, v, rng)


def checked_material(v: Any) -> Any:
    """A shape's material: an instance of rtpy.materials.Material (a built-in one or
    a student's subclass); TypeError naming `material` for anything else (a name, None),
    which would otherwise fail only when a ray hits the shape."""
    from .materials.material import Material  # (materials use these checks)

    if not isinstance(v, Material):
        found = (
            f"the string {v!r}" if isinstance(v, str) else f"{type(v).__name__} {_short(repr(v))}"
        )
        raise TypeError(f"material: expected a Material such as rtpy.Lambertian(), found {found}")
    return v
