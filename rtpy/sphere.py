"""Sphere: center and radius; the geometric normal points outward."""

from __future__ import annotations

import math

from .bvh import AABB
from .hit_info import HitInfo
from .hittable import Hittable
from .onb import local_to_world
from .ray import Ray
from .sampling import uniform_sphere
from .vec3 import Vec3


class Sphere(Hittable):
    def __init__(self, center: Vec3, radius: float, material) -> None:
        if not radius > 0.0:
            raise ValueError(f"sphere radius must be > 0, got {radius}")
        self.center = center
        self.radius = radius
        self.material = material
        # Plain floats for the hot intersection loop.
        self._cx, self._cy, self._cz = center.e0, center.e1, center.e2
        self._r2 = radius * radius

    def hit_t(self, ray: Ray, t_min: float, t_max: float) -> float | None:
        # BEGIN SOLUTION week04: the smallest root t of |o + t d - c|^2 = r^2 inside (t_min, t_max)
        o, d = ray.origin, ray.direction
        dx, dy, dz = d.e0, d.e1, d.e2
        ocx, ocy, ocz = self._cx - o.e0, self._cy - o.e1, self._cz - o.e2  # origin -> center
        h = dx * ocx + dy * ocy + dz * ocz
        c_term = ocx * ocx + ocy * ocy + ocz * ocz - self._r2  # > 0: origin outside
        if h < 0.0 and c_term > 0.0:
            return None  # outside and moving away
        a = dx * dx + dy * dy + dz * dz
        # The textbook discriminant h^2 - a*c cancels catastrophically for big
        # spheres seen from far away. a * (r^2 - |f|^2), with f the offset from
        # the center to the ray's closest point to it, is the same number
        # computed without cancellation (pbrt-v4, Ray Tracing Gems ch. 7).
        k = h / a
        fx, fy, fz = ocx - k * dx, ocy - k * dy, ocz - k * dz
        f2 = fx * fx + fy * fy + fz * fz
        if f2 > self._r2:
            return None  # the line passes the sphere by
        r, f = self.radius, math.sqrt(f2)
        disc = a * (r - f) * (r + f)
        # Roots (h -+ sqrt(disc)) / a, written as c/q and q/a so neither
        # subtracts two nearly equal numbers.
        q = h + math.copysign(math.sqrt(disc), h)
        if q == 0.0:
            return None
        t0 = c_term / q
        t1 = q / a
        if t0 > t1:
            t0, t1 = t1, t0
        if t_min < t0 < t_max:
            return t0
        if t_min < t1 < t_max:
            return t1
        return None
        # END SOLUTION

    def bounding_box(self) -> AABB:
        """center -+ radius on each axis, padded."""
        c, r = self.center, self.radius
        return AABB(Vec3(c.e0 - r, c.e1 - r, c.e2 - r), Vec3(c.e0 + r, c.e1 + r, c.e2 + r)).padded()

    def hit_info(self, ray: Ray, t: float) -> HitInfo:
        # BEGIN SOLUTION week04: hit point, unit normal facing the ray, front_face
        c, r = self.center, self.radius
        p = ray.at(t)
        nx, ny, nz = p.e0 - c.e0, p.e1 - c.e1, p.e2 - c.e2
        k = 1.0 / math.sqrt(nx * nx + ny * ny + nz * nz)
        nx, ny, nz = nx * k, ny * k, nz * k
        # Put the hit point back onto the surface: removes the rounding of o + t d.
        p = Vec3(c.e0 + r * nx, c.e1 + r * ny, c.e2 + r * nz)
        d = ray.direction
        front_face = d.e0 * nx + d.e1 * ny + d.e2 * nz < 0.0
        normal = Vec3(nx, ny, nz) if front_face else Vec3(-nx, -ny, -nz)
        return HitInfo(p, normal, t, front_face, self.material, self)
        # END SOLUTION

    def surface_uv(self, hit: HitInfo) -> tuple[float, float]:
        """RTIOW's spherical coordinates: u = phi / (2 pi) with phi measured from -x
        around +y; v = theta / pi with theta from -y (v = 0 at the south pole)."""
        # BEGIN SOLUTION week07: spherical (u, v) of the hit
        c, r = self.center, self.radius
        p = hit.point
        x, y, z = (p.e0 - c.e0) / r, (p.e1 - c.e1) / r, (p.e2 - c.e2) / r
        theta = math.acos(max(-1.0, min(1.0, -y)))
        phi = math.atan2(-z, x) + math.pi
        return phi / (2.0 * math.pi), theta / math.pi
        # END SOLUTION

    def surface_tangent(self, hit: HitInfo) -> Vec3 | None:
        """d(point)/du: along the circle of latitude, toward increasing phi."""
        c = self.center
        x, z = hit.point.e0 - c.e0, hit.point.e2 - c.e2
        length = math.hypot(x, z)
        if length < 1e-12 * self.radius:
            return None  # at a pole u has no direction
        return Vec3(z / length, 0.0, -x / length)

    def area(self) -> float:
        return 4.0 * math.pi * self.radius * self.radius

    def sample_point(self, r1: float, r2: float) -> tuple[Vec3, Vec3]:
        n = Vec3(*uniform_sphere(r1, r2))
        return self.center + n * self.radius, n

    # Sphere lights seen from outside are sampled uniformly in the cone of
    # directions they subtend (pbrt-v4's Sphere::Sample), which has far less
    # variance than sampling the area; from inside, uniformly by area.
    def _cone(self, p: Vec3) -> tuple[float, float] | None:
        """(cos_theta_max, 1 - cos_theta_max) of the cone the sphere subtends at p,
        or None when p is inside the sphere."""
        c = self.center
        dx, dy, dz = c.e0 - p.e0, c.e1 - p.e1, c.e2 - p.e2
        d2 = dx * dx + dy * dy + dz * dz
        r2 = self.radius * self.radius
        if d2 <= r2 * 1.0000001:
            return None
        sin2 = r2 / d2
        cos_max = math.sqrt(1.0 - sin2)
        return cos_max, sin2 / (1.0 + cos_max)  # 1 - cos_max without cancellation

    def sample_direction(self, p: Vec3, r1: float, r2: float) -> tuple[Vec3, float] | None:
        cone = self._cone(p)
        if cone is None:
            return super().sample_direction(p, r1, r2)
        cos_max, one_minus_cos_max = cone
        cos_t = 1.0 - r1 * one_minus_cos_max
        sin_t = math.sqrt(max(0.0, 1.0 - cos_t * cos_t))
        phi = 2.0 * math.pi * r2
        c = self.center
        axis = Vec3(c.e0 - p.e0, c.e1 - p.e1, c.e2 - p.e2)
        axis = axis / axis.length()
        direction = local_to_world(axis, sin_t * math.cos(phi), sin_t * math.sin(phi), cos_t)
        return direction, 1.0 / (2.0 * math.pi * one_minus_cos_max)

    def direction_pdf(self, p: Vec3, hit: HitInfo) -> float:
        cone = self._cone(p)
        if cone is None:
            return super().direction_pdf(p, hit)
        return 1.0 / (2.0 * math.pi * cone[1])
