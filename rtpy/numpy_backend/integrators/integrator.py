"""BatchIntegrator: turns camera rays into the radiance they carry back, many at once.

The batched twin of rtpy/integrators/integrator.py. Each integrator maps rays
(origins (N, 3), unit directions (N, 3)) to one radiance sample per ray (N, 3), with
the same estimator as its scalar twin. Paths run as a wavefront: every live path is
at the same segment, the whole batch is intersected, shaded by material kind, and
paths that end are dropped. Random numbers come from the numpy Generator passed in,
never a global one.
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from ...render_settings import RenderSettings

if TYPE_CHECKING:
    from ..scene import BatchScene


class BatchIntegrator:
    """Base class. compute_scattering(o, d, scene, rng) estimates, for every ray, the
    radiance arriving at its origin along -d (a Monte Carlo estimate for the
    stochastic integrators: its expectation is the pixel value)."""

    name = "integrator"
    uses_center_ray = False  # True: one ray through each pixel's center, spp = 1

    def __init__(self, settings: RenderSettings | None = None) -> None:
        self.settings = settings or RenderSettings()

    def compute_scattering(
        self, o: np.ndarray, d: np.ndarray, scene: BatchScene, rng: np.random.Generator
    ) -> np.ndarray:
        raise NotImplementedError


def first_hits(o: np.ndarray, d: np.ndarray, scene: BatchScene, out: np.ndarray):
    """The first hits of the rays (o, d): out's rows of the rays that miss get the
    background; (indices of the rays that hit, their HitBatch, their material ids),
    or None when none hits."""
    obj, t = scene.find_intersection(o, d)
    miss = obj < 0
    out[miss] = scene.background_radiance(d[miss])
    h = np.flatnonzero(~miss)
    if h.size == 0:
        return None
    return h, scene.hit_batch(obj[h], o[h], d[h], t[h]), scene.material_id[obj[h]]
