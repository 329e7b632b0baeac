"""The "shading" integrator: local shading of the first hit by every light, shadow
rays only with `shadows` (rtpy/integrators/shading.py)."""

from __future__ import annotations

import numpy as np

from ..arrays import add_rows
from ..sampler import first_hit_generator
from .direct_lighting import light_sample_estimate
from .integrator import BatchIntegrator, first_hits


class ShadingIntegrator(BatchIntegrator):
    """The background where a ray hits nothing, else the emission of the surface hit
    plus, at non-specular surfaces, one sample of every light: f_r L cos / pdf,
    black behind a blocker only when the settings' shadows is true."""

    name = "shading"

    def compute_scattering(self, o, d, scene, rng):
        out = np.zeros((len(o), 3))
        found = first_hits(o, d, scene, out)
        if found is None:
            return out
        h, hits, ids = found
        materials = scene.materials
        em = np.flatnonzero(materials.is_emitter[ids])
        if em.size:
            emitted = materials.emitting(ids[em], hits.take(em))
            add_rows(out, h[em], emitted)
        ns = np.flatnonzero(~materials.is_specular[ids])
        if ns.size == 0 or scene.lights.n == 0:
            return out
        part = hits if ns.size == h.size else hits.take(ns)
        draw = first_hit_generator(rng, h[ns], 1)  # a sampler's first-hit numbers
        for k in range(scene.lights.n):
            s = scene.lights.sample_chosen(part.point, np.full(ns.size, k), draw)
            light = light_sample_estimate(
                scene, part, ids[ns], s, 1, mis=False, shadows=self.settings.shadows
            )
            add_rows(out, h[ns], light)
        return out
