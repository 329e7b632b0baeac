"""Sphere lights for the scalar backend: Sphere.sample_hit's numbers, per component.

Light sampling of a sphere seen from outside (rtpy.sphere.Sphere.sample_hit: a
direction uniform in the cone the sphere subtends, the distance along it, the point
and normal there) runs at every bounce of every path. The course writes it as plain
Vec3 algebra, which makes about fifteen short-lived vectors per sample; SphereLight
computes the same floats, operation for operation, on three plain numbers each and
builds only the vectors it returns. The scalar backend renders with it in place of
an AreaLight whose shape is a Sphere (rtpy.engine.prepared_scene); a sphere light it
could not match bit for bit on probes (a Sphere subclass, an edited Sphere or
AreaLight) keeps the course's own method. tests/engine/test_sphere_lights.py checks
the floats against the course's. It and rtpy.engine.sphere_hits make the scalar
backend's speed (docs/performance.md#scalar-backend-against-an-older-commit).
"""

from __future__ import annotations

import math

from ..hit_info import HitInfo
from ..light import AreaLight, LightSample
from ..sampling import generator, use_generator
from ..sphere import Sphere
from ..vec3 import Vec3

__all__ = ["SphereLight", "matches", "sample_sphere_hit"]

TWO_PI = 2.0 * math.pi


def sample_sphere_hit(sphere: Sphere, p: Vec3, r1: float, r2: float):
    """sphere.sample_hit(p, r1, r2), the same floats, computed per component."""
    c, radius = sphere.center, sphere.radius
    ax, ay, az = c.e0 - p.e0, c.e1 - p.e1, c.e2 - p.e2  # to the center (Sphere._cone)
    d2 = ax * ax + ay * ay + az * az
    rr = radius * radius
    if d2 <= rr * 1.0000001:
        return sphere.sample_hit(p, r1, r2)  # inside: by area, the course's own way
    sin2 = rr / d2
    cone_size = sin2 / (1.0 + math.sqrt(1.0 - sin2))  # one_minus_cos_max
    distance = math.sqrt(d2)
    cos_t = 1.0 - r1 * cone_size  # cone_angle
    sin2_t = max(0.0, 1.0 - cos_t * cos_t)
    phi = TWO_PI * r2
    sin_t = math.sqrt(sin2_t)
    lx, ly, lz = sin_t * math.cos(phi), sin_t * math.sin(phi), cos_t
    k = 1.0 / distance  # axis / length, as Vec3.__truediv__ divides
    x, y, z = ax * k, ay * k, az * k
    sign = math.copysign(1.0, z)  # the frame ONB(axis) builds
    a = -1.0 / (sign + z)
    b = x * y * a
    u0, u1, u2 = 1.0 + sign * x * x * a, sign * b, -sign * x
    v0, v1, v2 = b, sign + y * y * a, -y
    d0 = u0 * lx + v0 * ly + x * lz  # ONB.to_world: u x + v y + w z
    d1 = u1 * lx + v1 * ly + y * lz
    dz = u2 * lx + v2 * ly + z * lz
    t = (d2 - rr) / (distance * cos_t + math.sqrt(max(0.0, rr - d2 * sin2_t)))  # nearer_root
    n0, n1, n2 = p.e0 + d0 * t - c.e0, p.e1 + d1 * t - c.e1, p.e2 + dz * t - c.e2
    k = 1.0 / math.sqrt(n0 * n0 + n1 * n1 + n2 * n2)  # unit_vector: v / |v|
    normal = Vec3(n0 * k, n1 * k, n2 * k)
    point = Vec3(c.e0 + normal.e0 * radius, c.e1 + normal.e1 * radius, c.e2 + normal.e2 * radius)
    pdf = 1.0 / (2.0 * math.pi * cone_size)  # cone_pdf
    hit = HitInfo(point, normal, t, True, sphere.material, sphere)
    return Vec3(d0, d1, dz), pdf, hit


class SphereLight:
    """The AreaLight of a Sphere, sampled by sample_sphere_hit: a stand-in with the
    interface of rtpy.light.Light that the integrators use (not one of the course's
    lights, so not a subclass)."""

    is_delta = False

    def __init__(self, light: AreaLight) -> None:
        self.light = light
        self.shape = light.shape

    def sample(self, p: Vec3) -> LightSample | None:
        """AreaLight.sample, the same draws and numbers."""
        r = generator().random
        shape = self.shape
        s = sample_sphere_hit(shape, p, r(), r())
        if s is None:
            return None
        direction, pdf, hit = s
        return LightSample(direction, hit.t, shape.material.emitting(hit), pdf, False, hit.point)

    def pdf(self, p: Vec3, hit: HitInfo) -> float:
        return self.light.pdf(p, hit)


# Probe points (in the sphere's radii from its center) and draws for matches():
# outside, near the surface and far away.
PROBES = [
    ((3.0, 0.5, -2.0), 0.3, 0.7),
    ((0.0, 1.0, 1.0), 0.999, 0.01),
    ((40.0, -7.0, 3.0), 0.5, 0.5),
]


class Draws:
    """A generator that gives the numbers it was made with, in turn."""

    def __init__(self, *numbers: float) -> None:
        self.random = iter(numbers).__next__


def numbers(sample: LightSample | None) -> tuple | None:
    """The floats of a light sample: direction, distance, radiance, pdf, point."""
    if sample is None:
        return None
    s = sample
    return s.direction.tolist(), s.distance, s.radiance.tolist(), s.pdf, s.point.tolist()


def matches(light: AreaLight) -> bool:
    """True when SphereLight(light) samples the numbers light.sample does on PROBES;
    False too when the course's code raises (a student's repository before the week
    that writes a function it calls): it raises again only if the render needs it."""
    ours = SphereLight(light)
    c, r = light.shape.center, light.shape.radius
    for (x, y, z), r1, r2 in PROBES:
        p = Vec3(c.e0 + x * r, c.e1 + y * r, c.e2 + z * r)
        with use_generator(Draws(r1, r2)):
            try:
                expected = numbers(light.sample(p))
            except Exception:  # whatever the course's code raises is its own to report
                return False
        with use_generator(Draws(r1, r2)):
            got = numbers(ours.sample(p))
        if expected is None or got != expected:
            return False
    return True
