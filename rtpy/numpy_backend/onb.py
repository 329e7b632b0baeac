"""Orthonormal bases around n unit vectors at once: the batched rtpy.onb.

Axes and local coordinates are Columns (three (n,) arrays, see vec3.py), where the
scalar ONB has Vec3s: ONB(axis).to_world(local) turns local coordinates (x, y, z)
into the world directions x u + y v + z w. The arithmetic is rtpy.onb's, operation
for operation, so a frame and the directions it maps agree with the scalar ones to
the last bit.
"""

from __future__ import annotations

import numpy as np

from .arrays import Rows
from .vec3 import Columns, components, cross, dot, stack, take


class ONB:
    """Frames (u, v, w) with w the given unit vectors; right-handed (u x v = w).

    ONB(w) is Duff et al. 2017's branchless frame ("Building an Orthonormal Basis,
    Revisited"), as rtpy.onb.ONB(w).
    """

    __slots__ = ("u", "v", "w")

    def __init__(self, w: Columns) -> None:
        w0, w1, w2 = w
        sign = np.copysign(1.0, w2)
        a = -1.0 / (sign + w2)
        b = w0 * w1 * a
        self.u = (1.0 + sign * w0 * w0 * a, sign * b, -sign * w0)
        self.v = (b, sign + w1 * w1 * a, -w1)
        self.w = w

    @classmethod
    def from_normal_tangent(cls, normal: Columns, tangent: Columns) -> ONB:
        """rtpy.onb.ONB.from_normal_tangent: w = normal, u = the tangent made
        perpendicular to it (Gram-Schmidt), v = w x u; ONB(normal) where the tangent
        lies along the normal (its perpendicular part shorter than 1e-9)."""
        k = dot(tangent, normal)
        u = tuple(tangent[c] - normal[c] * k for c in range(3))
        length = np.sqrt(dot(u, u))
        degenerate = length < 1e-9
        if degenerate.any():
            length = np.where(degenerate, 1.0, length)
        frame = cls.__new__(cls)
        inv = 1.0 / length  # as Vec3 / length: one reciprocal, three products
        frame.u = (u[0] * inv, u[1] * inv, u[2] * inv)
        frame.v = cross(normal, frame.u)
        frame.w = normal
        if degenerate.any():
            duff = cls(normal)
            frame.u = _where(degenerate, duff.u, frame.u)
            frame.v = _where(degenerate, duff.v, frame.v)
        return frame

    def take(self, rows: Rows) -> ONB:
        """The frames of the rows `rows`."""
        frame = ONB.__new__(ONB)
        frame.u, frame.v, frame.w = take(self.u, rows), take(self.v, rows), take(self.w, rows)
        return frame

    def to_local(self, d: Columns) -> Columns:
        """Coordinates (x, y, z) of the world vectors d in the frames (z along w)."""
        return dot(d, self.u), dot(d, self.v), dot(d, self.w)

    def to_world(self, a: Columns) -> Columns:
        """The world vectors x u + y v + z w of the local coordinates a = (x, y, z)."""
        u, v, w = self.u, self.v, self.w
        x, y, z = a
        return (
            x * u[0] + y * v[0] + z * w[0],
            x * u[1] + y * v[1] + z * w[1],
            x * u[2] + y * v[2] + z * w[2],
        )


def _where(mask: np.ndarray, a: Columns, b: Columns) -> Columns:
    return tuple(np.where(mask, x, y) for x, y in zip(a, b, strict=True))


def local_to_world(w: Columns, x: np.ndarray, y: np.ndarray, z: np.ndarray) -> Columns:
    """ONB(w).to_world of rtpy.onb: x u + y v + z w for the frames ONB(w) builds, without
    building them (the same numbers, as in the scalar code)."""
    w0, w1, w2 = w
    sign = np.copysign(1.0, w2)
    a = -1.0 / (sign + w2)
    b = w0 * w1 * a
    return (
        x * (1.0 + sign * w0 * w0 * a) + y * b + z * w0,
        x * sign * b + y * (sign + w1 * w1 * a) + z * w1,
        -x * sign * w0 - y * w1 + z * w2,
    )


def tangent_of(normal: np.ndarray) -> np.ndarray:
    """(n, 3) first axes u of ONB(normal): HitInfo.tangent where the surface gives none."""
    return stack(*ONB(components(normal)).u)
