"""Sphere hits for the scalar backend: Sphere.hit_t's numbers, per component.

Every ray of a path tests every sphere of a small scene (rtpy.sphere.Sphere.hit_t,
called by Scene.find_intersection and find_occlusion and by the BVH's leaves). The
course writes the test as Vec3 algebra, which makes three short-lived vectors per
test, and the hit found as many more (Sphere.hit_info); sphere_hit_t and
sphere_hit_info compute the same floats, operation for operation, on plain numbers.
The scalar backend renders with FastSphere copies of the scene's spheres
(rtpy.engine.prepared_scene) once they have given the course's own numbers on
PROBES; a Sphere subclass, or an edited Sphere.hit_t or hit_info that differs on a
probe, keeps the course's methods. tests/engine/test_sphere_hits.py checks the floats.

It holds week 4's answer, so a student's repository leaves it out
(rtpy.grading.assignment): renders there run the student's own methods.
"""

from __future__ import annotations

import math

from ..hit_info import HitInfo
from ..materials import Lambertian
from ..ray import Ray
from ..sphere import Sphere
from ..vec3 import Color, Vec3

__all__ = ["FastSphere", "fast_copy", "hits_match", "sphere_hit_info", "sphere_hit_t"]


def sphere_hit_t(sphere: Sphere, ray: Ray, t_min: float, t_max: float) -> float | None:
    """sphere.hit_t(ray, t_min, t_max), the same floats, computed per component."""
    c, o, d = sphere.center, ray.origin, ray.direction
    radius = sphere.radius
    r2 = radius * radius
    ox, oy, oz = c.e0 - o.e0, c.e1 - o.e1, c.e2 - o.e2  # oc: to the center
    dx, dy, dz = d.e0, d.e1, d.e2
    oc2 = ox * ox + oy * oy + oz * oz
    h = dx * ox + dy * oy + dz * oz
    c2 = oc2 - r2
    if h < 0.0 and c2 > 0.0:
        return None
    a = dx * dx + dy * dy + dz * dz
    if h * h - a * c2 < -1e-14 * a * oc2:
        return None
    k = h / a
    fx, fy, fz = ox - dx * k, oy - dy * k, oz - dz * k  # oc - d * (h / a)
    f2 = fx * fx + fy * fy + fz * fz
    if f2 > r2:
        return None
    f = math.sqrt(f2)
    disc = a * (radius - f) * (radius + f)
    q = h + math.copysign(math.sqrt(disc), h)
    if q == 0.0:
        return None
    t0 = c2 / q
    t1 = q / a
    if t0 > t1:
        t0, t1 = t1, t0
    if t_min < t0 < t_max:
        return t0
    if t_min < t1 < t_max:
        return t1
    return None


def sphere_hit_info(sphere: Sphere, ray: Ray, t: float) -> HitInfo:
    """sphere.hit_info(ray, t), the same floats, computed per component."""
    c, o, d = sphere.center, ray.origin, ray.direction
    x, y, z = o.e0 + d.e0 * t - c.e0, o.e1 + d.e1 * t - c.e1, o.e2 + d.e2 * t - c.e2
    k = 1.0 / math.sqrt(x * x + y * y + z * z)  # unit_vector: v * (1 / |v|)
    x, y, z = x * k, y * k, z * k
    r = sphere.radius
    point = Vec3(c.e0 + x * r, c.e1 + y * r, c.e2 + z * r)
    front_face = d.e0 * x + d.e1 * y + d.e2 * z < 0.0
    normal = Vec3(x, y, z) if front_face else Vec3(-x, -y, -z)
    return HitInfo(point, normal, t, front_face, sphere.material, sphere)


class FastSphere(Sphere):
    """A Sphere whose hit_t and hit_info are sphere_hit_t and sphere_hit_info: the
    scalar backend's copy of a scene's sphere (the same attributes, so the same
    pdfs and samples)."""

    hit_t = sphere_hit_t
    hit_info = sphere_hit_info


def fast_copy(sphere: Sphere) -> FastSphere:
    """A FastSphere holding the attributes of `sphere` (not copied themselves)."""
    fast = object.__new__(FastSphere)
    fast.__dict__.update(vars(sphere))
    return fast


# Probe rays (origin, direction, t_min, t_max) against a sphere of radius 0.7 at
# (0.2, -0.1, -1.5): from outside, from inside, past it, grazing, just past it (where
# only the test without cancellation tells), behind the origin, ended by t_max after
# the hit and before it, from a spawned origin on the surface, and unnormalised. They
# end hit_t at each of its returns but the degenerate q == 0 (test_sphere_hits.py).
PROBES = [
    ((0.0, 0.0, 0.0), (0.0, 0.0, -1.0), 1e-9, math.inf),
    ((0.1, 0.2, -1.4), (0.3, -0.5, 0.8), 0.0, math.inf),
    ((0.0, 0.0, 0.0), (1.0, 0.0, 0.0), 0.0, math.inf),
    ((0.9, 5.0, -1.5), (0.0, -1.0, 0.0), 0.0, math.inf),
    ((0.9000000000001, 5.0, -1.5), (0.0, -1.0, 0.0), 0.0, math.inf),
    ((0.0, 0.0, -4.0), (0.0, 0.0, -1.0), 0.0, math.inf),
    ((0.0, 0.0, 0.0), (0.1, -0.05, -1.0), 0.0, 1.0),
    ((0.0, 0.0, 0.0), (0.1, -0.05, -1.0), 0.0, 0.5),
    ((0.2, -0.1, -0.8000000007), (0.0, 0.6, 0.8), 0.0, math.inf),
    ((-3.0, 2.0, 1.0), (6.4, -4.2, -5.0), 0.001, 0.9),
]
PROBE_SPHERE = ((0.2, -0.1, -1.5), 0.7)


def hit_numbers(hit: HitInfo) -> tuple:
    return hit.point.tolist(), hit.normal.tolist(), hit.t, hit.front_face, hit.material, hit.obj


def hits_match() -> bool:
    """True when sphere_hit_t and sphere_hit_info give the numbers Sphere.hit_t and
    Sphere.hit_info do on PROBES; False too when the course's code raises (a task not
    written yet): it is its own to report."""
    center, radius = PROBE_SPHERE
    sphere = Sphere(Vec3(*center), radius, Lambertian(Color(0.5, 0.5, 0.5)))
    for origin, direction, t_min, t_max in PROBES:
        ray = Ray(Vec3(*origin), Vec3(*direction))
        try:
            expected = Sphere.hit_t(sphere, ray, t_min, t_max)
            info = None if expected is None else hit_numbers(Sphere.hit_info(sphere, ray, expected))
        except Exception:
            return False
        if sphere_hit_t(sphere, ray, t_min, t_max) != expected:
            return False
        if info is not None and hit_numbers(sphere_hit_info(sphere, ray, expected)) != info:
            return False
    return True
