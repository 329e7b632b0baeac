"""The "whitted" integrator (rtpy/integrators/whitted.py): direct light at diffuse
surfaces, perfect reflection and refraction at mirrors and glass."""

from __future__ import annotations

import numpy as np

from ..ray import spawn_origins
from .direct_lighting import direct_lighting
from .integrator import BatchIntegrator

# Whitted's specular rays branch; batches are processed depth first in chunks of
# at most this many rays, so memory stays bounded however deep the recursion goes.
WHITTED_CHUNK = 8192


class WhittedIntegrator(BatchIntegrator):
    """Whitted-style ray tracing as rtpy.integrators.WhittedIntegrator: at a
    non-specular hit emission + direct light, at a specular hit the material's
    deterministic rays (reflection R, refraction 1 - R), up to max_depth segments.
    The scalar recursion becomes a stack of batches of rays at one depth."""

    name = "whitted"

    def compute_scattering(self, o, d, scene, rng):
        n = len(o)
        result = np.zeros((n, 3))
        max_depth = self.settings.max_depth
        # Depth-first over batches: (origins, directions, weights, camera rays, depth).
        stack = [(o, d, np.ones((n, 3)), np.arange(n), 1)]
        materials = scene.materials
        while stack:
            o, d, w, paths, depth = stack.pop()
            if len(paths) > WHITTED_CHUNK:
                for s in range(len(paths) - WHITTED_CHUNK, -WHITTED_CHUNK, -WHITTED_CHUNK):
                    sl = slice(max(s, 0), s + WHITTED_CHUNK)
                    stack.append((o[sl], d[sl], w[sl], paths[sl], depth))
                continue
            obj, t = scene.find_intersection(o, d)
            miss = obj < 0
            np.add.at(result, paths[miss], w[miss] * scene.background_radiance(d[miss]))
            h = np.flatnonzero(~miss)
            if h.size == 0:
                continue
            o, d, w, paths, obj, t = o[h], d[h], w[h], paths[h], obj[h], t[h]
            hits = scene.hit_batch(obj, o, d, t)
            ids = scene.material_id[obj]
            em = np.flatnonzero(materials.is_emitter[ids])
            if em.size:
                emitted = materials.emitting(ids[em], hits.take(em))
                np.add.at(result, paths[em], w[em] * emitted)
            if depth >= max_depth:
                continue
            spec = materials.is_specular[ids]
            ns = np.flatnonzero(~spec)
            if ns.size:
                part = hits if ns.size == len(ids) else hits.take(ns)
                direct = direct_lighting(scene, part, ids[ns], rng)
                np.add.at(result, paths[ns], w[ns] * direct)
            sp = np.flatnonzero(spec)
            if sp.size == 0:
                continue
            part = hits.take(sp)
            children = []
            for direction, weight, mask in materials.specular_rays(ids[sp], part):
                k = np.flatnonzero(mask)
                if k.size == 0:
                    continue
                origin = spawn_origins(part.point[k], part.normal[k], direction[k])
                children.append((origin, direction[k], w[sp[k]] * weight[k], paths[sp[k]]))
            if children:
                stack.append((*(np.concatenate(c) for c in zip(*children, strict=True)), depth + 1))
        return result
