"""Integrator: turns a camera ray into the radiance it carries back."""

from __future__ import annotations

import math

from ..interval import Interval
from ..ray import Ray
from ..render_settings import RenderSettings
from ..scene import Scene
from ..vec3 import Color

# Rays spawned by rtpy start off their surface (see ray.spawn_ray), so every
# search for a hit can run over all t > 0.
FORWARD = Interval(0.0, math.inf)


class Integrator:
    """Base class: compute_scattering(ray, scene) is the radiance a camera ray
    brings back."""

    name = "integrator"
    uses_center_ray = False  # True: one ray through each pixel's center, spp = 1

    def __init__(self, settings: RenderSettings | None = None) -> None:
        self.settings = settings or RenderSettings()

    def compute_scattering(self, ray: Ray, scene: Scene) -> Color:
        """The radiance arriving at ray.origin along -ray.direction: for the
        stochastic integrators a Monte Carlo estimate whose expectation is the pixel
        value. The course's name; `radiance` is the same method."""
        raise NotImplementedError

    def radiance(self, ray: Ray, scene: Scene) -> Color:
        """compute_scattering, under the name of what it returns."""
        return self.compute_scattering(ray, scene)
