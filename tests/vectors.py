"""Plain-tuple vector helpers for the tests, written independently of rtpy.vec3, so that
expected values do not come from the code under test."""

from __future__ import annotations

import math

from rtpy.vec3 import Vec3


def V(x, y, z) -> Vec3:
    return Vec3(float(x), float(y), float(z))


def dot3(a, b) -> float:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def cross3(a, b):
    return (a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0])


def sub3(a, b):
    return (a[0] - b[0], a[1] - b[1], a[2] - b[2])


def norm3(a) -> float:
    return math.sqrt(dot3(a, a))


def unit3(a):
    k = 1.0 / norm3(a)
    return (a[0] * k, a[1] * k, a[2] * k)


def angle(a, b) -> float:
    """Angle between two vectors, accurate for small angles (atan2 of |a x b| and a.b)."""
    return math.atan2(norm3(cross3(a, b)), dot3(a, b))
