"""The "jittered" integrator: the flat colour averaged over random rays inside each
pixel (rtpy/integrators/jittered.py)."""

from __future__ import annotations

from .center import flat_color
from .integrator import BatchIntegrator


class JitteredIntegrator(BatchIntegrator):
    name = "jittered"

    def compute_scattering(self, o, d, scene, rng):
        return flat_color(o, d, scene)
