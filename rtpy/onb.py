"""Orthonormal basis: a frame (u, v, w) around a unit vector w.

Sampling draws a direction in a frame with its z axis along some axis (the normal
for a diffuse bounce, the mirror direction for a Phong highlight): a Vec3 of local
coordinates (x, y, z). ONB(axis).to_world(local) turns it into the world direction
x u + y v + z w.
"""

from __future__ import annotations

import math

from .vec3 import Vec3, cross, dot


class ONB:
    """Frame (u, v, w) with w the given unit vector; right-handed (u x v = w).

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
        u = tangent - normal * dot(tangent, normal)
        length = u.length()
        if length < 1e-9:  # tangent along the normal: any frame will do
            return cls(normal)
        frame = cls.__new__(cls)
        frame.u = u / length
        frame.v = cross(normal, frame.u)
        frame.w = normal
        return frame

    def to_local(self, d: Vec3) -> Vec3:
        """Coordinates (x, y, z) of the world vector d in this frame (z along w)."""
        return Vec3(dot(d, self.u), dot(d, self.v), dot(d, self.w))

    def to_world(self, a: Vec3) -> Vec3:
        """The world vector x u + y v + z w of the local coordinates a = (x, y, z)."""
        # Written per component: every bounce of a path calls this, and one Vec3
        # costs less than the five that u * x + v * y + w * z would make.
        u, v, w = self.u, self.v, self.w
        x, y, z = a.e0, a.e1, a.e2
        return Vec3(
            x * u.e0 + y * v.e0 + z * w.e0,
            x * u.e1 + y * v.e1 + z * w.e1,
            x * u.e2 + y * v.e2 + z * w.e2,
        )


def local_to_world(w: Vec3 | tuple[float, float, float], x: float, y: float, z: float) -> Vec3:
    """x * u + y * v + z * w for the frame ONB(w) builds, without building it
    (the same numbers). w is a unit Vec3 or its three components."""
    w0, w1, w2 = w
    sign = math.copysign(1.0, w2)
    a = -1.0 / (sign + w2)
    b = w0 * w1 * a
    return Vec3(
        x * (1.0 + sign * w0 * w0 * a) + y * b + z * w0,
        x * sign * b + y * (sign + w1 * w1 * a) + z * w1,
        -x * sign * w0 - y * w1 + z * w2,
    )
