"""The "center" integrator: flat colour of the first hit (rtpy/integrators/center.py)."""

from __future__ import annotations

import numpy as np

from ..arrays import max3
from ..scene import BatchScene
from .integrator import BatchIntegrator


def flat_color(o: np.ndarray, d: np.ndarray, scene: BatchScene) -> np.ndarray:
    """(N, 3): emitted radiance where a ray hits an emitter's emitting face, else the
    albedo (texture value) of the surface hit, else the background."""
    out = np.empty((len(o), 3))
    obj, t = scene.find_intersection(o, d)
    miss = obj < 0
    out[miss] = scene.background_radiance(d[miss])
    h = np.flatnonzero(~miss)
    if h.size == 0:
        return out
    hits = scene.hit_batch(obj[h], o[h], d[h], t[h])
    materials = scene.materials
    ids = scene.material_id[obj[h]]
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
