"""Triangle with vertices a, b, c."""

from __future__ import annotations

import math

from ._checks import MIN_AREA, checked_material, checked_point
from .bvh import AABB
from .hit_info import HitInfo
from .hittable import FlatShape
from .ray import Ray
from .vec3 import Vec3, cross, dot

# Moller-Trumbore divides by det = e1 . (d x e2), which is |e1| |e2| |d| times
# about the sine of the angle between the ray and the triangle's plane. When that
# sine is below this, det is mostly rounding error and (t, u, v) could report a
# "hit" far from the triangle, so the ray counts as parallel (the classic
# algorithm's epsilon, made relative to the sizes).
PARALLEL_TOLERANCE = 1e-6


class Triangle(FlatShape):
    """Front face normal = normalize((b - a) x (c - a)).

    Surface coordinates (u, v) are the barycentric weights of b and c, so the
    triangle is the half of Quad(a, b - a, c - a) with u + v <= 1 and shares its
    texture mapping.
    """

    def __init__(self, a: Vec3, b: Vec3, c: Vec3, material) -> None:
        a, b, c = checked_point("a", a), checked_point("b", b), checked_point("c", c)
        material = checked_material(material)
        self._place(a, b, c, material)

    def _place(self, a: Vec3, b: Vec3, c: Vec3, material) -> None:
        """The triangle's edges, normal and the rest, from points already checked (a
        Mesh checks its vertices all at once)."""
        self.a, self.b, self.c = a, b, c
        self.e1 = b - a
        self.e2 = c - a
        n = cross(self.e1, self.e2)
        n_len = n.length()  # twice the area
        if not n_len >= MIN_AREA:
            raise ValueError(
                f"triangle a, b, c is degenerate: twice its area is {n_len:.3g} < {MIN_AREA:g}"
            )
        self.normal = n / n_len
        self.material = material
        self._area = 0.5 * n_len
        self._tangent = self.e1 / self.e1.length()  # u runs from a toward b
        # surface_uv solves for (u, v) in the coordinate plane the triangle is least
        # tilted from: the one across the axis of the normal's largest component.
        drop = max(range(3), key=lambda c: abs(n[c]))
        self._plane_axes = ((drop + 1) % 3, (drop + 2) % 3)
        self._plane_det = n[drop]  # the projected twice-area, at least n_len / sqrt(3)
        # det^2 <= _parallel_det2 * |d|^2 means parallel
        self._parallel_det2 = (PARALLEL_TOLERANCE * self.e1.length() * self.e2.length()) ** 2

    def _barycentric(self, ray: Ray) -> tuple[float, float, float] | None:
        """Moller-Trumbore: (t, u, v) of the ray's hit with the triangle's plane
        inside the triangle, or None."""
        # BEGIN SOLUTION week04: Moller-Trumbore: (t, u, v) inside the triangle, or None
        d = ray.direction
        p = cross(d, self.e2)
        det = dot(self.e1, p)
        if det * det <= self._parallel_det2 * d.length_squared():
            return None  # parallel to the plane, within rounding
        inv = 1.0 / det
        s = ray.origin - self.a
        u = dot(s, p) * inv
        if u < 0.0 or u > 1.0:
            return None
        q = cross(s, self.e1)
        v = dot(d, q) * inv
        if v < 0.0 or u + v > 1.0:
            return None
        t = dot(self.e2, q) * inv
        return t, u, v
        # END SOLUTION

    def hit_t(self, ray: Ray, t_min: float, t_max: float) -> float | None:
        r = self._barycentric(ray)
        if r is None or not t_min < r[0] < t_max:
            return None
        return r[0]

    def bounding_box(self) -> AABB:
        """The box around the three vertices; padded, so an axis-aligned triangle's
        box is not flat."""
        return AABB.from_points(self.a, self.b, self.c).padded()

    def hit_info(self, ray: Ray, t: float) -> HitInfo:
        n = self.normal
        front_face = dot(n, ray.direction) < 0.0
        return HitInfo(ray.at(t), n if front_face else -n, t, front_face, self.material, self)

    def surface_uv(self, hit: HitInfo) -> tuple[float, float]:
        # Barycentric coordinates of the hit point, p - a = u e1 + v e2, by Cramer's
        # rule on two of the three equations: those of the plane the triangle is least
        # tilted from (Badouel 1990), whose determinant is largest. The normal
        # equations would square the condition number and lose every digit on a long
        # thin triangle (edges 5e5 long, 1e-6 apart).
        p = hit.point - self.a
        i, j = self._plane_axes
        e1, e2 = self.e1, self.e2
        u = (p[i] * e2[j] - p[j] * e2[i]) / self._plane_det
        v = (e1[i] * p[j] - e1[j] * p[i]) / self._plane_det
        return min(1.0, max(0.0, u)), min(1.0, max(0.0, v))

    def sample_point(self, r1: float, r2: float) -> tuple[Vec3, Vec3]:
        wb, wc = triangle_weights(r1, r2)
        return self.a + self.e1 * wb + self.e2 * wc, self.normal


def triangle_weights(r1: float, r2: float) -> tuple[float, float]:
    """The barycentric weights (of b, of c) of a point uniform by area on a triangle,
    from two uniform numbers: s = sqrt(r1) warps the unit square onto the triangle."""
    s = math.sqrt(r1)
    return s * (1.0 - r2), s * r2
