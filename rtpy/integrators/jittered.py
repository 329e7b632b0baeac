"""The "jittered" integrator (course week 3): the flat colour averaged over
random rays inside each pixel."""

from __future__ import annotations

from ..ray import Ray
from ..scene import Scene
from ..vec3 import Color
from .center import flat_color
from .integrator import Integrator


class JitteredIntegrator(Integrator):
    name = "jittered"

    def compute_scattering(self, ray: Ray, scene: Scene) -> Color:
        return flat_color(ray, scene)
