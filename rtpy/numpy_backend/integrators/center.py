"""The "center" integrator: flat colour of the first hit (rtpy/integrators/center.py)."""

from __future__ import annotations

import numpy as np

from ..arrays import max3
from ..scene import BatchScene
from .integrator import BatchIntegrator, first_hits


def flat_color(o: np.ndarray, d: np.ndarray, scene: BatchScene) -> np.ndarray:
    """(N, 3): emitted radiance where a ray hits an emitter's emitting face, else the
    albedo (texture value) of the surface hit, else the background."""
    out = np.empty((len(o), 3))
    found = first_hits(o, d, scene, out)
    if found is None:
        return out
    h, hits, ids = found
    materials = scene.materials
    color = np.zeros((h.size, 3))
    flat = np.ones(h.size, dtype=bool)
    em = np.flatnonzero(materials.is_emitter[ids])
    if em.size:
        emitted = materials.emitting(ids[em], hits.take(em))
        glowing = max3(emitted) > 0.0  # not black (emission is >= 0)
        color[em[glowing]] = emitted[glowing]
        flat[em[glowing]] = False
    f = np.flatnonzero(flat)
    if f.size:
        part = hits if f.size == h.size else hits.take(f)
        color[f] = materials.flat_color(ids[f], part)
    out[h] = color
    return out


class CenterIntegrator(BatchIntegrator):
    """One ray through each pixel's center; no lighting at all."""

    name = "center"
    uses_center_ray = True

    def compute_scattering(self, o, d, scene, rng):
        return flat_color(o, d, scene)
