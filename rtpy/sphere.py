"""Sphere: center and radius; the geometric normal points outward."""

from __future__ import annotations

import math

from ._checks import LENGTH, checked_material, checked_number, checked_point
from .bvh import AABB
from .hit_info import HitInfo
from .hittable import Hittable
from .onb import ONB
from .ray import Ray
from .sampling import cone_angle, cone_pdf, uniform_sphere
from .vec3 import Vec3, dot, unit_vector


class Sphere(Hittable):
    def __init__(self, center: Vec3, radius: float, material) -> None:
        self.center = checked_point("center", center)
        self.radius = checked_number("radius", radius, LENGTH)
        self.material = checked_material(material)

    def hit_t(self, ray: Ray, t_min: float, t_max: float) -> float | None:
        # BEGIN SOLUTION week04: the smallest root t of |o + t d - c|^2 = r^2 inside (t_min, t_max)
        d, r2 = ray.direction, self.radius * self.radius
        oc = self.center - ray.origin  # from the ray's origin to the center
        oc2 = oc.length_squared()
        h = dot(d, oc)
        c = oc2 - r2  # > 0: the origin is outside
        if h < 0.0 and c > 0.0:
            return None  # outside and moving away
        a = d.length_squared()
        # The textbook discriminant h^2 - a c tells a hit from a miss, but for big
        # spheres seen from far away it cancels: its rounding error reaches about
        # 1e-15 a |oc|^2. Clearly below that, the line passes the sphere by.
        if h * h - a * c < -1e-14 * a * oc2:
            return None
        # Elsewhere a * (r^2 - |f|^2), with f the offset from the center to the ray's
        # closest point to it, is the same number computed without cancellation
        # (pbrt-v4, Ray Tracing Gems ch. 7).
        f2 = (oc - d * (h / a)).length_squared()
        if f2 > r2:
            return None  # the line passes the sphere by
        r, f = self.radius, math.sqrt(f2)
        disc = a * (r - f) * (r + f)
        # Roots (h -+ sqrt(disc)) / a, written as c/q and q/a so neither
        # subtracts two nearly equal numbers.
        q = h + math.copysign(math.sqrt(disc), h)
        if q == 0.0:
            return None
        t0 = c / q
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
        extent = Vec3(self.radius, self.radius, self.radius)
        return AABB(self.center - extent, self.center + extent).padded()

    def hit_info(self, ray: Ray, t: float) -> HitInfo:
        # BEGIN SOLUTION week04: hit point, unit normal facing the ray, front_face
        outward = unit_vector(ray.at(t) - self.center)
        # The hit point put back onto the surface: removes the rounding of o + t d.
        point = self.center + outward * self.radius
        front_face = dot(ray.direction, outward) < 0.0
        normal = outward if front_face else -outward
        return HitInfo(point, normal, t, front_face, self.material, self)
        # END SOLUTION

    def surface_uv(self, hit: HitInfo) -> tuple[float, float]:
        """RTIOW's spherical coordinates: u = phi / (2 pi) with phi measured from -x
        around +y; v = theta / pi with theta from -y (v = 0 at the south pole)."""
        # BEGIN SOLUTION week07: spherical (u, v) of the hit
        n = (hit.point - self.center) / self.radius  # the outward unit normal
        theta = math.acos(max(-1.0, min(1.0, -n.y())))
        phi = math.atan2(-n.z(), n.x()) + math.pi
        return phi / (2.0 * math.pi), theta / math.pi
        # END SOLUTION

    def surface_tangent(self, hit: HitInfo) -> Vec3 | None:
        """d(point)/du: along the circle of latitude, toward increasing phi."""
        offset = hit.point - self.center
        x, z = offset.x(), offset.z()
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
    def _cone(self, p: Vec3) -> tuple[Vec3, float, float] | None:
        """(the vector from p to the center, its squared length, 1 - cos_theta_max of
        the cone the sphere subtends at p), or None when p is inside the sphere."""
        to_center = self.center - p
        d2 = to_center.length_squared()
        r2 = self.radius * self.radius
        if d2 <= r2 * 1.0000001:
            return None
        return to_center, d2, one_minus_cos_max(r2, d2)

    def sample_direction(self, p: Vec3, r1: float, r2: float) -> tuple[Vec3, float] | None:
        if self._cone(p) is None:
            return super().sample_direction(p, r1, r2)
        direction, pdf, _ = self.sample_hit(p, r1, r2)
        return direction, pdf

    def sample_hit(self, p: Vec3, r1: float, r2: float) -> tuple[Vec3, float, HitInfo] | None:
        """As Hittable.sample_hit. From outside, the direction is drawn uniformly in
        the cone the sphere subtends at p, and the distance to the sphere follows from
        the sampled angle, so the ray is not traced."""
        cone = self._cone(p)
        if cone is None:
            return super().sample_hit(p, r1, r2)  # inside: by area
        to_center, d2, cone_size = cone
        distance = math.sqrt(d2)
        cos_t, sin2_t = cone_angle(r1, cone_size)  # theta, from the axis to the center
        phi = 2.0 * math.pi * r2  # around the axis
        direction = direction_around(to_center, distance, cos_t, math.sqrt(sin2_t), phi)
        t = nearer_root(d2, self.radius * self.radius, distance, cos_t, sin2_t)
        normal, point = self.surface_along(p, direction, t)
        return direction, cone_pdf(cone_size), HitInfo(point, normal, t, True, self.material, self)

    def surface_along(self, p: Vec3, direction: Vec3, t: float) -> tuple[Vec3, Vec3]:
        """(outward normal, point) where the ray from p along direction meets the
        sphere at t: the point put back onto the surface, as hit_info puts it."""
        normal = unit_vector(p + direction * t - self.center)
        return normal, self.center + normal * self.radius

    def direction_pdf(self, p: Vec3, hit: HitInfo) -> float:
        cone = self._cone(p)
        if cone is None:
            return super().direction_pdf(p, hit)
        return cone_pdf(cone[2])


# --- the cone a sphere subtends ------------------------------------------------------


def one_minus_cos_max(r2: float, d2: float) -> float:
    """1 - cos_theta_max of the cone a sphere of squared radius r2 subtends at squared
    distance d2 from its center: sin^2 / (1 + cos) with sin^2 = r2 / d2, which does not
    cancel for small cones as 1 - sqrt(1 - sin^2) would."""
    sin2 = r2 / d2
    return sin2 / (1.0 + math.sqrt(1.0 - sin2))


def direction_around(axis: Vec3, length: float, cos_t: float, sin_t: float, phi: float) -> Vec3:
    """The unit direction at angle theta (cos_t, sin_t) from axis / length (axis a
    vector of that length) and at azimuth phi around it, in the frame ONB builds."""
    local = Vec3(sin_t * math.cos(phi), sin_t * math.sin(phi), cos_t)
    return ONB(axis / length).to_world(local)


def nearer_root(d2: float, r2: float, distance: float, cos_t: float, sin2_t: float) -> float:
    """How far a ray from a point at `distance` from a sphere's center (d2 = distance^2,
    r2 = radius^2) goes to the sphere, sent at angle theta (cos_t, sin2_t = sin^2) from
    the direction to the center, inside the cone: the nearer root of
    t^2 - 2 t D cos_t + D^2 - r^2 = 0, as (D^2 - r^2) / (D cos_t + sqrt(r^2 - D^2 sin^2_t))
    without cancellation (inside the cone the square root's argument is >= 0 but for
    rounding)."""
    return (d2 - r2) / (distance * cos_t + math.sqrt(max(0.0, r2 - d2 * sin2_t)))
