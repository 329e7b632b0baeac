"""Kernel of Metal (rtpy/materials/metal.py)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ...materials import Metal
from ..hit_info import HitBatch
from ..sampling import uniform_sphere
from ..scatter_info import ScatterBatch
from ..vec3 import components, dot, stack, take
from .material import param
from .mirror import MirrorKernel


class MetalKernel(MirrorKernel):
    """unit(reflection + fuzz * uniform unit vector), absorbed below the surface; the
    Whitted ray is the perfect reflection."""

    def __init__(self, materials: Sequence[Metal]) -> None:
        super().__init__(materials)
        self.fuzz = param(self.materials, "fuzz")

    def scattering(
        self, slots: np.ndarray, hits: HitBatch, rng: np.random.Generator
    ) -> ScatterBatch:
        out = super().scattering(slots, hits, rng)
        fuzz = self.fuzz[slots]
        fuzzy = np.flatnonzero(fuzz > 0.0)
        if len(fuzzy) == 0:
            return out
        r = rng.random((2, len(fuzzy)))
        s = uniform_sphere(r[0], r[1])
        f = fuzz[fuzzy]
        d = components(out.direction[fuzzy])
        d = (d[0] + s[0] * f, d[1] + s[1] * f, d[2] + s[2] * f)
        alive = ~((np.abs(d[0]) < 1e-12) & (np.abs(d[1]) < 1e-12) & (np.abs(d[2]) < 1e-12))
        length2 = np.where(alive, dot(d, d), 1.0)
        k = 1.0 / np.sqrt(length2)
        d = (d[0] * k, d[1] * k, d[2] * k)
        alive &= dot(d, take(components(hits.normal), fuzzy)) > 0.0  # else absorbed
        out.direction[fuzzy] = np.where(alive[:, None], stack(*d), 0.0)
        out.attenuation[fuzzy] *= alive[:, None]
        out.alive[fuzzy] = alive
        out.is_specular[fuzzy] = alive
        return out
