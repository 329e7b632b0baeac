"""Quad: the parallelogram q + a*u + b*v with a, b in [0, 1]."""

from __future__ import annotations

from ._checks import MIN_AREA, checked_edge, checked_material, checked_point
from .bvh import AABB
from .hit_info import HitInfo
from .hittable import FlatShape
from .ray import Ray
from .vec3 import Vec3, cross, dot


class Quad(FlatShape):
    """Front face normal = normalize(u x v); surface coordinates (u, v) = (a, b)."""

    def __init__(self, q: Vec3, u: Vec3, v: Vec3, material) -> None:
        q = checked_point("q", q)
        u = checked_edge("u", u)
        v = checked_edge("v", v)
        n = cross(u, v)
        n_len = n.length()
        if not n_len >= MIN_AREA:
            raise ValueError(
                f"quad is degenerate: u and v are parallel (|u x v| = {n_len:.3g} < {MIN_AREA:g})"
            )
        self.q, self.u, self.v = q, u, v
        self.material = checked_material(material)
        self.normal = n / n_len
        self.d = dot(self.normal, q)  # plane: dot(normal, p) = d
        self.w = n / dot(n, n)  # turns a planar vector into (a, b) coordinates
        self._area = n_len
        self._tangent = u / u.length()

    def _coords(self, p: Vec3) -> tuple[float, float]:
        # BEGIN SOLUTION week04: the planar coordinates (alpha, beta) of p: p = q + alpha u + beta v
        planar = p - self.q
        alpha = dot(self.w, cross(planar, self.v))
        beta = dot(self.w, cross(self.u, planar))
        return alpha, beta
        # END SOLUTION

    def hit_t(self, ray: Ray, t_min: float, t_max: float) -> float | None:
        # BEGIN SOLUTION week04: plane intersection, then the interior test 0 <= alpha, beta <= 1
        denom = dot(self.normal, ray.direction)
        if denom == 0.0:
            return None  # parallel to the plane
        t = (self.d - dot(self.normal, ray.origin)) / denom
        if not t_min < t < t_max:
            return None
        alpha, beta = self._coords(ray.at(t))
        if 0.0 <= alpha <= 1.0 and 0.0 <= beta <= 1.0:
            return t
        return None
        # END SOLUTION

    def bounding_box(self) -> AABB:
        """The box around the four corners; padded, so an axis-aligned quad's box
        is not flat."""
        q, u, v = self.q, self.u, self.v
        return AABB.from_points(q, q + u, q + v, q + u + v).padded()

    def hit_info(self, ray: Ray, t: float) -> HitInfo:
        n = self.normal
        front_face = dot(n, ray.direction) < 0.0
        return HitInfo(ray.at(t), n if front_face else -n, t, front_face, self.material, self)

    def surface_uv(self, hit: HitInfo) -> tuple[float, float]:
        # BEGIN SOLUTION week07: (u, v) = (alpha, beta) of the hit
        a, b = self._coords(hit.point)
        return min(1.0, max(0.0, a)), min(1.0, max(0.0, b))
        # END SOLUTION

    def sample_point(self, r1: float, r2: float) -> tuple[Vec3, Vec3]:
        return self.q + self.u * r1 + self.v * r2, self.normal
