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
        x, y, z = w.x(), w.y(), w.z()
        sign = math.copysign(1.0, z)
        a = -1.0 / (sign + z)
        b = x * y * a
        self.u = Vec3(1.0 + sign * x * x * a, sign * b, -sign * x)
        self.v = Vec3(b, sign + y * y * a, -y)
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
        return self.u * a.x() + self.v * a.y() + self.w * a.z()
