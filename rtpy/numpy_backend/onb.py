"""Orthonormal bases around n unit normals at once: the batched rtpy.onb.

Axes are Columns (three (n,) arrays, see vec3.py). The arithmetic is rtpy.onb's,
operation for operation, so a frame and the directions it maps agree with the
scalar ones to the last bit.
"""

from __future__ import annotations

import numpy as np

from .arrays import Rows
from .vec3 import Columns, components, dot, stack, take


class ONB:
    """Frames (u, v, w) with w the given unit vectors; right-handed.

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
    def from_normal_tangent(cls, normal: np.ndarray, tangent: np.ndarray) -> ONB:
        """rtpy.onb.ONB.from_normal_tangent for (n, 3) arrays: w = normal, u = the
        tangent made perpendicular to it (Gram-Schmidt), v = w x u; ONB(normal) where
        the tangent lies along the normal (its perpendicular part shorter than 1e-9)."""
        w = components(normal)
        t = components(tangent)
        k = dot(t, w)
        ux, uy, uz = t[0] - k * w[0], t[1] - k * w[1], t[2] - k * w[2]
        length = np.sqrt(ux * ux + uy * uy + uz * uz)
        degenerate = length < 1e-9
        if degenerate.any():
            length = np.where(degenerate, 1.0, length)
        frame = cls.__new__(cls)
        frame.w = w
        inv = 1.0 / length  # as Vec3 / length: one reciprocal, three products
        frame.u = (ux * inv, uy * inv, uz * inv)
        u = frame.u
        frame.v = (
            w[1] * u[2] - w[2] * u[1],
            w[2] * u[0] - w[0] * u[2],
            w[0] * u[1] - w[1] * u[0],
        )
        if degenerate.any():
            duff = cls(w)
            frame.u = _where(degenerate, duff.u, frame.u)
            frame.v = _where(degenerate, duff.v, frame.v)
        return frame

    def take(self, rows: Rows) -> ONB:
        """The frames of the rows `rows`."""
        frame = ONB.__new__(ONB)
        frame.u, frame.v, frame.w = take(self.u, rows), take(self.v, rows), take(self.w, rows)
        return frame

    def to_local(self, d: np.ndarray) -> Columns:
        """Coordinates (x, y, z) of the world vectors d (n, 3) in the frames (z along w)."""
        d = components(d)
        return dot(d, self.u), dot(d, self.v), dot(d, self.w)

    def to_world(self, x: np.ndarray, y: np.ndarray, z: np.ndarray) -> Columns:
        """x u + y v + z w."""
        u, v, w = self.u, self.v, self.w
        return (
            x * u[0] + y * v[0] + z * w[0],
            x * u[1] + y * v[1] + z * w[1],
            x * u[2] + y * v[2] + z * w[2],
        )


def _where(mask: np.ndarray, a: Columns, b: Columns) -> Columns:
    return tuple(np.where(mask, x, y) for x, y in zip(a, b, strict=True))


def local_to_world(w: Columns, x: np.ndarray, y: np.ndarray, z: np.ndarray) -> Columns:
    """rtpy.onb.local_to_world: x u + y v + z w for the frames ONB(w) builds, without
    building them (the same numbers, as in the scalar code; the hot path of every
    diffuse bounce)."""
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
