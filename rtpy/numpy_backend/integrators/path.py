"""The "path" integrator: unbiased path tracing (rtpy/integrators/path.py), as a wavefront."""

from __future__ import annotations

import numpy as np

from ..arrays import add_rows, divide, max3, rows
from ..ray import spawn_origins
from ..sampler import first_hit_generator
from .direct_lighting import Bounce, add_emission, sample_one_light
from .integrator import BatchIntegrator


class PathIntegrator(BatchIntegrator):
    """The estimator of rtpy.integrators.PathIntegrator, for all camera rays at once.

    At every vertex: add the emission found there (MIS-weighted against light
    sampling), add a light-sampling estimate (next-event estimation) at non-specular
    hits, then continue along the direction scattering() samples, multiplying the
    path throughput `beta` by its weight BRDF * cos / pdf. max_depth counts ray
    segments, the camera ray included; after segment `russian_roulette` a path
    survives with probability q and is divided by it: min(0.95, max(beta)), or
    roulette_probability with roulette = "fixed". nee = False
    samples only point lights; mis = False adds area lights by light sampling alone.

    All live paths advance one segment per iteration; `paths` holds the camera ray
    each belongs to, and paths that end are dropped from every array.
    """

    name = "path"

    def _limits(self) -> tuple[int, int, bool]:
        s = self.settings
        return s.max_depth, s.russian_roulette, s.nee

    def _survival(self, bmax: np.ndarray) -> np.ndarray:
        """Russian roulette's q per path from its throughput's largest component
        (PathIntegrator.survival_probability)."""
        if self.settings.roulette == "fixed":
            return np.full(bmax.shape, self.settings.roulette_probability)
        return np.minimum(0.95, bmax)

    def compute_scattering(self, o, d, scene, rng):
        max_depth, rr_start, nee = self._limits()
        n = len(o)
        result = np.zeros((n, 3))
        n_lights = scene.lights.count(include_area=nee)
        n_mis = n_lights if nee else 0  # lights that MIS weights account for
        mis = self.settings.mis
        materials = scene.materials
        paths = np.arange(n)  # the camera ray each live path belongs to
        beta = np.ones((n, 3))
        prev = Bounce.camera(n)
        segment = 1
        while paths.size:
            obj, t = scene.find_intersection(o, d)
            miss = obj < 0
            if miss.any():
                m = np.flatnonzero(miss)
                add_rows(
                    result, paths[m], beta.take(m, axis=0) * scene.background_radiance(rows(d, m))
                )
                keep = np.flatnonzero(~miss)
                paths, obj, t = paths.take(keep), obj.take(keep), t.take(keep)
                o, d, beta, prev = rows(o, keep), rows(d, keep), rows(beta, keep), prev.take(keep)
                if paths.size == 0:
                    break
            hits = scene.hit_batch(obj, o, d, t)
            add_emission(scene, result, paths, beta, obj, hits, prev, n_mis, mis)
            if segment >= max_depth:
                break
            ids = scene.material_id.take(obj)
            inert = materials.inert.take(ids)
            if inert.any():  # paths end on lights that reflect nothing (no kernel split)
                k = np.flatnonzero(~inert)
                paths, ids, hits, beta = paths.take(k), ids.take(k), hits.take(k), rows(beta, k)
                if paths.size == 0:
                    break
            draw = first_hit_generator(rng, paths, segment)  # a sampler's first-hit numbers
            if n_lights:
                add_direct_light(result, paths, beta, scene, hits, ids, draw, nee, mis)
            sc = materials.scattering(ids, hits, draw)
            beta = beta * sc.attenuation
            bmax = max3(beta)
            alive = sc.alive & (bmax > 0.0)
            roulette = bool(rr_start and segment >= rr_start)
            if roulette:
                survive = self._survival(bmax)
                alive &= rng.random(paths.size) < survive
            a = np.flatnonzero(alive)
            if a.size == paths.size:  # nothing ended: no compaction
                point, normal, d = hits.point, hits.normal, sc.direction
                prev = Bounce(point, sc.pdf, sc.is_specular)
            else:
                paths, beta = paths.take(a), rows(beta, a)
                point, normal = rows(hits.point, a), rows(hits.normal, a)
                d = rows(sc.direction, a)
                prev = Bounce(point, sc.pdf.take(a), sc.is_specular.take(a))
                if roulette:
                    survive = survive.take(a)
            if roulette:
                beta = divide(beta, survive)
            o = spawn_origins(point, normal, d)
            segment += 1
        return result


def add_direct_light(result, paths, beta, scene, hits, ids, rng, nee: bool, mis: bool) -> None:
    """result[paths] += beta * sample_one_light at the hits on non-specular materials
    (all lights with nee, else the point lights only)."""
    ns = np.flatnonzero(~scene.materials.is_specular.take(ids))
    if ns.size == len(paths):
        direct = sample_one_light(scene, hits, ids, rng, nee, mis)
        direct *= beta
        add_rows(result, paths, direct)
    elif ns.size:
        direct = sample_one_light(scene, hits.take(ns), ids.take(ns), rng, nee, mis)
        direct *= rows(beta, ns)
        add_rows(result, paths.take(ns), direct)
