"""Orthonormal basis around a unit normal (local frame with z = normal)."""

from __future__ import annotations

import math

from .vec3 import Vec3


class ONB:
    """Frame (u, v, w) with w the given unit vector; right-handed.

    Built with the branchless method of Duff et al. 2017 ("Building an
    Orthonormal Basis, Revisited"), which is stable for every w.
    """

    __slots__ = ("u", "v", "w")

    def __init__(self, w: Vec3) -> None:
        sign = math.copysign(1.0, w.e2)
        a = -1.0 / (sign + w.e2)
        b = w.e0 * w.e1 * a
        self.u = Vec3(1.0 + sign * w.e0 * w.e0 * a, sign * b, -sign * w.e0)
        self.v = Vec3(b, sign + w.e1 * w.e1 * a, -w.e1)
        self.w = w

    @classmethod
    def from_normal_tangent(cls, normal: Vec3, tangent: Vec3) -> ONB:
        """Frame with w = normal and u = the tangent made perpendicular to it
        (Gram-Schmidt); v = w x u."""
        frame = cls.__new__(cls)
        k = tangent.e0 * normal.e0 + tangent.e1 * normal.e1 + tangent.e2 * normal.e2
        ux = tangent.e0 - k * normal.e0
        uy = tangent.e1 - k * normal.e1
        uz = tangent.e2 - k * normal.e2
        length = math.sqrt(ux * ux + uy * uy + uz * uz)
        if length < 1e-9:  # tangent along the normal: any frame will do
            return cls(normal)
        u = Vec3(ux / length, uy / length, uz / length)
        w = normal
        frame.u = u
        frame.v = Vec3(
            w.e1 * u.e2 - w.e2 * u.e1, w.e2 * u.e0 - w.e0 * u.e2, w.e0 * u.e1 - w.e1 * u.e0
        )
        frame.w = w
        return frame

    def to_local(self, d: Vec3) -> tuple[float, float, float]:
        """Coordinates (x, y, z) of the world vector d in this frame (z along w)."""
        u, v, w = self.u, self.v, self.w
        return (
            d.e0 * u.e0 + d.e1 * u.e1 + d.e2 * u.e2,
            d.e0 * v.e0 + d.e1 * v.e1 + d.e2 * v.e2,
            d.e0 * w.e0 + d.e1 * w.e1 + d.e2 * w.e2,
        )

    def to_world(self, x: float, y: float, z: float) -> Vec3:
        u, v, w = self.u, self.v, self.w
        return Vec3(
            x * u.e0 + y * v.e0 + z * w.e0,
            x * u.e1 + y * v.e1 + z * w.e1,
            x * u.e2 + y * v.e2 + z * w.e2,
        )


def local_to_world(w: Vec3, x: float, y: float, z: float) -> Vec3:
    """x * u + y * v + z * w for the frame ONB(w) builds, without building it
    (the same numbers; this is the hot path of every diffuse bounce)."""
    w0, w1, w2 = w.e0, w.e1, w.e2
    sign = math.copysign(1.0, w2)
    a = -1.0 / (sign + w2)
    b = w0 * w1 * a
    return Vec3(
        x * (1.0 + sign * w0 * w0 * a) + y * b + z * w0,
        x * sign * b + y * (sign + w1 * w1 * a) + z * w1,
        -x * sign * w0 - y * w1 + z * w2,
    )
