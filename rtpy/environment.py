"""Environments: radiance that arrives from infinitely far away, by direction.

A ray that escapes the scene sees the scene's environment when it has one
(`Scene(environment=...)`, Python API only), else the `sky` gradient or the
constant `background`. Integrators reach an environment only by BRDF sampling
(it is not light-sampled), so every integrator still counts it exactly once.

Convention: `direction` is the escaping ray's direction, pointing away from the
scene (not necessarily unit length); world y is up.
"""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from ._checks import RADIANCE, Range, checked_color, checked_number
from .vec3 import Color, Vec3

if TYPE_CHECKING:
    import numpy as np

POLAR_ANGLE = Range(0, 180)  # degrees from the zenith


class Environment:
    """Base class: radiance(direction) for one ray (the scalar backend) and
    radiance_array(directions) for an (N, 3) array of them (the numpy backend;
    by default one call of radiance per row)."""

    def radiance(self, direction: Vec3) -> Color:
        raise NotImplementedError

    def radiance_array(self, d: np.ndarray) -> np.ndarray:
        import numpy as np  # the numpy backend's; the scalar renderer needs no numpy

        out = np.empty((len(d), 3))
        for k, row in enumerate(d):
            c = self.radiance(Vec3(*row))
            out[k] = c.tolist()
        return out


class SkyBand(Environment):
    """Radiance `radiance` from the directions whose angle from the zenith (+y)
    lies in [theta_min, theta_max] (degrees, 0 = straight up, 90 = the horizon),
    black elsewhere. A surface facing up receives the irradiance
    E = radiance * pi * (sin^2 theta_max - sin^2 theta_min)."""

    def __init__(self, radiance: Color, theta_min: float, theta_max: float) -> None:
        self.value = checked_color("radiance", radiance, RADIANCE)
        self.theta_min = checked_number("theta_min", theta_min, POLAR_ANGLE)
        self.theta_max = checked_number("theta_max", theta_max, POLAR_ANGLE)
        if not self.theta_min < self.theta_max:
            raise ValueError(
                f"theta_max: expected more than theta_min = {theta_min}, found {theta_max}"
            )
        self._cos_hi = math.cos(math.radians(self.theta_min))  # cos falls as theta grows
        self._cos_lo = math.cos(math.radians(self.theta_max))

    def irradiance_up(self) -> Color:
        """Irradiance on a surface whose normal is +y, from the band (closed form)."""
        s1, s2 = (math.sin(math.radians(t)) for t in (self.theta_min, self.theta_max))
        if self.theta_max > 90.0:  # the part below the horizon does not reach it
            s2 = 1.0
        return self.value * (math.pi * (s2 * s2 - s1 * s1))

    def radiance(self, direction: Vec3) -> Color:
        cos_theta = direction.y() / direction.length()
        if self._cos_lo <= cos_theta <= self._cos_hi:
            return self.value
        return Color(0.0, 0.0, 0.0)

    def radiance_array(self, d: np.ndarray) -> np.ndarray:
        import numpy as np

        # Twin of radiance kept: einsum's sum of squares is not length()'s order.
        cos_theta = d[:, 1] / np.sqrt(np.einsum("ij,ij->i", d, d))
        inside = (cos_theta >= self._cos_lo) & (cos_theta <= self._cos_hi)
        value = np.array(self.value.tolist())
        return inside[:, None] * value
