"""Vec3 and Color: three plain floats with the vector algebra of the course.

`Vec3` is used for points, directions and normals. `Color` is a Vec3 whose
components are read as linear RGB (r(), g(), b()). Both store their three
components in the slots ``e0, e1, e2`` (like RTIOW's ``e[0..2]``); the
accessors ``x()``, ``y()``, ``z()`` read them.

Arithmetic keeps the type of the left operand, so ``Color * float`` is a
Color and ``Vec3 + Vec3`` is a Vec3. ``a * b`` with two vectors multiplies
component-wise (used for colours); use ``dot`` for the scalar product.
"""

from __future__ import annotations

import math


class Vec3:
    __slots__ = ("e0", "e1", "e2")

    def __init__(self, e0: float = 0.0, e1: float = 0.0, e2: float = 0.0) -> None:
        self.e0 = e0
        self.e1 = e1
        self.e2 = e2

    # --- components -------------------------------------------------------
    def x(self) -> float:
        return self.e0

    def y(self) -> float:
        return self.e1

    def z(self) -> float:
        return self.e2

    def __getitem__(self, i: int) -> float:
        return (self.e0, self.e1, self.e2)[i]

    def __iter__(self):
        return iter((self.e0, self.e1, self.e2))

    def __len__(self) -> int:
        return 3

    def tolist(self) -> list[float]:
        return [self.e0, self.e1, self.e2]

    # --- arithmetic -------------------------------------------------------
    # Each result has the type of the left operand: a Color stays a Color.
    def __add__(self, o: Vec3) -> Vec3:
        return type(self)(self.e0 + o.e0, self.e1 + o.e1, self.e2 + o.e2)

    def __sub__(self, o: Vec3) -> Vec3:
        return type(self)(self.e0 - o.e0, self.e1 - o.e1, self.e2 - o.e2)

    def __neg__(self) -> Vec3:
        return type(self)(-self.e0, -self.e1, -self.e2)

    def __mul__(self, o: Vec3 | float) -> Vec3:
        if type(o) is float or not isinstance(o, Vec3):
            return type(self)(self.e0 * o, self.e1 * o, self.e2 * o)
        return type(self)(self.e0 * o.e0, self.e1 * o.e1, self.e2 * o.e2)  # for colours

    def __rmul__(self, s: float) -> Vec3:
        return type(self)(self.e0 * s, self.e1 * s, self.e2 * s)

    def __truediv__(self, s: float) -> Vec3:
        k = 1.0 / s  # v / s as (1 / s) v, as RTIOW's operator/ computes it
        return type(self)(self.e0 * k, self.e1 * k, self.e2 * k)

    def __eq__(self, o: object) -> bool:
        if not isinstance(o, Vec3):
            return NotImplemented
        return self.e0 == o.e0 and self.e1 == o.e1 and self.e2 == o.e2

    __hash__ = None  # mutable-looking value type: not hashable

    def __repr__(self) -> str:
        return f"{self.__class__.__name__}({self.e0!r}, {self.e1!r}, {self.e2!r})"

    # --- geometry ---------------------------------------------------------
    def length_squared(self) -> float:
        return self.e0 * self.e0 + self.e1 * self.e1 + self.e2 * self.e2

    def length(self) -> float:
        return math.sqrt(self.e0 * self.e0 + self.e1 * self.e1 + self.e2 * self.e2)

    def near_zero(self, eps: float = 1e-8) -> bool:
        """True when every component is smaller than eps in magnitude."""
        return abs(self.e0) < eps and abs(self.e1) < eps and abs(self.e2) < eps

    def max_component(self) -> float:
        return max(self.e0, self.e1, self.e2)

    def is_black(self) -> bool:
        return self.e0 == 0.0 and self.e1 == 0.0 and self.e2 == 0.0


class Color(Vec3):
    """Linear RGB radiance, irradiance or reflectance."""

    __slots__ = ()

    # r(), g(), b(): the components x(), y(), z() under their colour names
    r, g, b = Vec3.x, Vec3.y, Vec3.z


Point3 = Vec3


def dot(a: Vec3, b: Vec3) -> float:
    return a.e0 * b.e0 + a.e1 * b.e1 + a.e2 * b.e2


def cross(a: Vec3, b: Vec3) -> Vec3:
    # BEGIN SOLUTION week03: the cross product a x b
    return Vec3(
        a.e1 * b.e2 - a.e2 * b.e1,
        a.e2 * b.e0 - a.e0 * b.e2,
        a.e0 * b.e1 - a.e1 * b.e0,
    )
    # END SOLUTION


def unit_vector(v: Vec3) -> Vec3:
    """v / |v|. The zero vector has no direction and raises ZeroDivisionError."""
    # BEGIN SOLUTION week03: v / |v|
    return v / v.length()
    # END SOLUTION


def reflect(v: Vec3, n: Vec3) -> Vec3:
    """Mirror v about the plane with unit normal n (v points toward the surface)."""
    # BEGIN SOLUTION week06: mirror v about the unit normal n
    return v - n * (2.0 * dot(v, n))
    # END SOLUTION


def refract(uv: Vec3, n: Vec3, etai_over_etat: float) -> Vec3:
    """Snell refraction of the unit vector uv (pointing toward the surface) through
    the unit normal n facing it. The caller checks for total internal reflection."""
    # BEGIN SOLUTION week06: Snell refraction of uv through n
    cos_theta = min(-dot(uv, n), 1.0)
    perp = (uv + n * cos_theta) * etai_over_etat
    parallel = n * -math.sqrt(abs(1.0 - perp.length_squared()))
    return perp + parallel
    # END SOLUTION


def halfvector(view: Vec3, light: Vec3) -> Vec3:
    """The unit half vector h = (view + light) / |view + light|, halfway between the
    unit directions to the viewer and to the light (both pointing away from the
    surface). Blinn-Phong, Cook-Torrance and Ward evaluate their highlights at h.
    view = -light has no half vector (ZeroDivisionError); above a surface they never
    are, since both lie on the normal's side."""
    return unit_vector(view + light)


BLACK = Color(0.0, 0.0, 0.0)
WHITE = Color(1.0, 1.0, 1.0)


# The course's names for three of the functions above, as Vec3's static methods
# (`Vec3.dot_product(u, v)` is `dot(u, v)`), so the course's spelling works too.
Vec3.dot_product = staticmethod(dot)
Vec3.cross_product = staticmethod(cross)
Vec3.unit_vector = staticmethod(unit_vector)
