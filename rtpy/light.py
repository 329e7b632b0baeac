"""Lights: point lights and area lights (objects with an emitting material).

A light is sampled from a receiving point p. The sample gives the unit
direction wi from p toward the light, the distance to it, the radiance L that
arrives along wi, and the solid-angle pdf of wi, so the direct-light estimate
is f_r * L * cos(theta_i) / pdf. A point light is a delta light: there is only
one direction, its "pdf" is 1 and L is already the irradiance I / d^2 at normal
incidence (radiant intensity falls off with the square of the distance).
"""

from __future__ import annotations

import math

from ._checks import RADIANCE, checked_color, checked_point
from .hit_info import HitInfo
from .hittable import MIN_LIGHT_DISTANCE2, Hittable
from .sampling import generator
from .vec3 import Color, Vec3


class LightSample:
    __slots__ = ("direction", "distance", "radiance", "pdf", "is_delta", "point")

    def __init__(
        self,
        direction: Vec3,
        distance: float,
        radiance: Color,
        pdf: float,
        is_delta: bool,
        point: Vec3,
    ) -> None:
        self.direction = direction  # unit, from the receiving point toward the light
        self.distance = distance
        self.radiance = radiance
        self.pdf = pdf
        self.is_delta = is_delta
        self.point = point  # the point on the light


class Light:
    is_delta = False
    shape: Hittable | None = None  # the emitting object of an area light

    def sample(self, p: Vec3) -> LightSample | None:
        raise NotImplementedError


class PointLight(Light):
    """Emits radiant intensity `intensity` (W/sr per channel) equally in all
    directions from `position`: a surface at distance d whose normal makes angle
    theta with the direction to the light receives irradiance I cos(theta) / d^2."""

    is_delta = True

    def __init__(self, position: Vec3, intensity: Color) -> None:
        self.position = checked_point("position", position)
        self.intensity = checked_color("intensity", intensity, RADIANCE)

    def sample(self, p: Vec3) -> LightSample | None:
        """The light seen from p: the unit direction from p toward the light, the
        distance d, the radiance I / d^2 arriving at p, pdf 1 and is_delta True (one
        direction only), and the light's position as the sampled point; None when p
        is the light's position, or nearer it than sqrt(MIN_LIGHT_DISTANCE2)."""
        # BEGIN SOLUTION week05: direction, distance and radiance I / d^2 seen from p
        to_light = self.position - p
        dist2 = to_light.length_squared()
        if dist2 < MIN_LIGHT_DISTANCE2:
            return None  # at the light: I / d^2 would overflow
        dist = math.sqrt(dist2)
        return LightSample(to_light / dist, dist, self.intensity / dist2, 1.0, True, self.position)
        # END SOLUTION


class AreaLight(Light):
    """An object whose material emits (DiffuseLight), sampled by its shape's
    sample_direction (by area, or by solid angle for spheres seen from outside)."""

    def __init__(self, shape: Hittable) -> None:
        self.shape = shape

    def sample(self, p: Vec3) -> LightSample | None:
        r = generator().random
        s = self.shape.sample_hit(p, r(), r())
        if s is None:
            return None
        direction, pdf, hit = s
        emitted = self.shape.material.emitting(hit)
        return LightSample(direction, hit.t, emitted, pdf, False, hit.point)

    def pdf(self, p: Vec3, hit: HitInfo) -> float:
        """Solid-angle density of sample(p) choosing the direction toward `hit`."""
        return self.shape.direction_pdf(p, hit)
