"""Direct lighting for many hits at once: the twin of rtpy/integrators/direct_lighting.py.

Light sampling (next-event estimation: one light, one direction toward it, a shadow
ray) and BRDF sampling (the direction scattering() picks, which may meet a light)
are combined by multiple importance sampling with the power heuristic, so light is
counted once. Point lights can only be reached by light sampling (weight 1).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..arrays import add_rows, dot, max3, put_rows, rows, scale
from ..hit_info import HitBatch
from ..light import LightSamples
from ..ray import offset_scale, spawn_origins
from ..sampling import power_heuristic
from ..scene import BatchScene


def sample_one_light(
    scene: BatchScene,
    hits: HitBatch,
    ids: np.ndarray,
    rng: np.random.Generator,
    include_area: bool = True,
    mis: bool = True,
) -> np.ndarray:
    """Light-sampling estimate (N, 3) of the radiance reflected toward hits.wo by light
    arriving directly from one light chosen uniformly (among the point lights only,
    without include_area): f_r L cos(theta_i) / pdf, times the MIS weight for area
    lights (with mis = False the weight is 1: light sampling alone). ids are the
    hits' material ids."""
    n_lights = scene.lights.count(include_area)
    s = scene.lights.sample(hits.point, rng, include_area)
    return light_sample_estimate(scene, hits, ids, s, n_lights, mis)


def light_sample_estimate(
    scene: BatchScene,
    hits: HitBatch,
    ids: np.ndarray,
    s: LightSamples,
    n_lights: int,
    mis: bool = True,
    shadows: bool = True,
) -> np.ndarray:
    """The estimate (N, 3) of the light samples s, each its light picked with
    probability 1 / n_lights: f_r L cos(theta_i) / pdf times n_lights and the MIS
    weight of area lights (1 without mis), 0 where a shadow ray is blocked (no shadow
    rays without shadows: the "shading" integrator's first rung)."""
    n = len(hits)
    out = np.zeros((n, 3))
    cos = dot(hits.normal, s.direction)
    cos_i = np.abs(cos)  # behind the surface: BRDF 0 unless glass
    ok = s.valid & (max3(s.radiance) > 0.0) & (cos_i > 0.0)
    idx = np.flatnonzero(ok)
    if idx.size == 0:
        return out
    whole = idx.size == n
    part = hits if whole else hits.take(idx)
    ids = ids if whole else ids.take(idx)
    wi = s.direction if whole else rows(s.direction, idx)
    # f_r, and for the MIS weight the density with which BRDF sampling picks wi
    if mis:
        f, brdf_pdf = scene.materials.BRDF_and_pdf(ids, part, wi)
    else:
        f, brdf_pdf = scene.materials.BRDF(ids, part, wi), None
    keep = np.flatnonzero(max3(f) > 0.0)
    if keep.size == 0:
        return out
    if keep.size < idx.size:
        idx, wi, f, part = idx.take(keep), rows(wi, keep), rows(f, keep), part.take(keep)
        brdf_pdf = None if brdf_pdf is None else brdf_pdf.take(keep)
    blocked = shadowed(scene, part, wi, cos.take(idx), s, idx) if shadows else None
    if blocked is not None and blocked.any():
        keep = np.flatnonzero(~blocked)
        idx, f = idx.take(keep), rows(f, keep)
        brdf_pdf = None if brdf_pdf is None else brdf_pdf.take(keep)
    pdf = s.pdf.take(idx) / n_lights  # choosing this light, then this direction
    if mis:
        weight = np.where(s.is_delta.take(idx), 1.0, power_heuristic(pdf, brdf_pdf))
    else:
        weight = np.ones(idx.size)
    contrib = scale(f * rows(s.radiance, idx), cos_i.take(idx) * weight / pdf)
    put_rows(out, idx, contrib)
    return out


def shadowed(scene: BatchScene, part: HitBatch, wi, cos, s: LightSamples, idx) -> np.ndarray:
    """(M,) bool: the shadow ray from each hit of part toward rows idx of the light
    samples s (directions wi, cosines cos with the normals) is blocked."""
    offset = offset_scale(part.point)
    origin = spawn_origins(part.point, part.normal, wi, offset, cos)
    # Stop the shadow ray just short of the light's surface, and let the light
    # itself not block it: the spawned origin is off the point the light was
    # sampled from, so the shadow ray can meet the light's surface a little
    # before `distance` (by far more than the offsets where it arrives at a
    # slant), and a convex light cannot hide its own sampled point.
    t_max = s.distance.take(idx) - offset_scale(rows(s.point, idx)) - offset
    return scene.find_occlusion(origin, wi, t_max, ignore=s.obj.take(idx))


@dataclass
class Bounce:
    """Where the rays that reached a batch of hits came from, as the scalar path loop's
    prev_point, prev_pdf and prev_specular: the vertex each ray left (None for camera
    rays), the solid-angle pdf its direction was drawn with, and whether that bounce
    was specular."""

    point: np.ndarray | None
    pdf: np.ndarray
    specular: np.ndarray

    @classmethod
    def camera(cls, n: int) -> Bounce:
        """n camera rays: no vertex, counted as specular (no light sampling there)."""
        return cls(None, np.zeros(n), np.ones(n, dtype=bool))

    def take(self, k: np.ndarray) -> Bounce:
        point = None if self.point is None else rows(self.point, k)
        return Bounce(point, self.pdf.take(k), self.specular.take(k))


def emission_weight(
    scene: BatchScene, obj: np.ndarray, hits: HitBatch, prev: Bounce, n_mis: int, mis: bool = True
) -> np.ndarray:
    """MIS weight (N,) of emission found by BRDF sampling at the hits on objects obj,
    reached from `prev`: 1 after the camera, after a specular bounce, or when lights
    are not sampled (n_mis = 0); 0 after other bounces if not mis (light sampling
    alone counts it)."""
    w = np.ones(len(obj))
    if n_mis == 0 or prev.point is None:
        return w
    if not mis:
        return prev.specular.astype(np.float64)
    m = np.flatnonzero(~prev.specular)
    if m.size == len(obj):
        light_pdf = scene.lights.direction_pdf(obj, prev.point, hits.point, hits.normal)
        return power_heuristic(prev.pdf, light_pdf / n_mis)
    if m.size:
        light_pdf = scene.lights.direction_pdf(
            obj.take(m), rows(prev.point, m), rows(hits.point, m), rows(hits.normal, m)
        )
        w[m] = power_heuristic(prev.pdf.take(m), light_pdf / n_mis)
    return w


def add_emission(
    scene: BatchScene,
    result: np.ndarray,
    paths: np.ndarray,
    beta: np.ndarray,
    obj: np.ndarray,
    hits: HitBatch,
    prev: Bounce,
    n_mis: int,
    mis: bool,
) -> None:
    """result[paths] += beta * emitted * emission_weight at the hits of paths `paths`
    on emitting objects (obj: the object each hit is on)."""
    materials = scene.materials
    ids = scene.material_id.take(obj)
    em = materials.is_emitter.take(ids)
    if not em.any():
        return
    e = np.flatnonzero(em)
    if e.size == len(ids):
        emitted = materials.emitting(ids, hits)
        w = emission_weight(scene, obj, hits, prev, n_mis, mis)
        add_rows(result, paths, scale(beta * emitted, w))
        return
    part = hits.take(e)
    emitted = materials.emitting(ids.take(e), part)
    w = emission_weight(scene, obj.take(e), part, prev.take(e), n_mis, mis)
    add_rows(result, paths.take(e), scale(rows(beta, e) * emitted, w))


def direct_lighting(
    scene: BatchScene, hits: HitBatch, ids: np.ndarray, rng: np.random.Generator
) -> np.ndarray:
    """Radiance (N, 3) reflected at non-specular hits after exactly one bounce: light
    sampling of all lights plus one BRDF-sampled ray that sees the background or an
    emitter, combined by MIS."""
    n = len(hits)
    n_lights = scene.lights.n
    result = sample_one_light(scene, hits, ids, rng) if n_lights else np.zeros((n, 3))
    sc = scene.materials.scattering(ids, hits, rng)
    a = np.flatnonzero(sc.alive)
    if a.size == 0:
        return result
    d = sc.direction[a]
    o = spawn_origins(hits.point[a], hits.normal[a], d)
    att = sc.attenuation[a]
    obj, t = scene.find_intersection(o, d)
    miss = obj < 0
    result[a[miss]] += att[miss] * scene.background_radiance(d[miss])
    h = np.flatnonzero(~miss)
    if h.size:
        nids = scene.material_id[obj[h]]
        if scene.materials.is_emitter[nids].any():
            nh = scene.hit_batch(obj[h], o[h], d[h], t[h])
            prev = Bounce(hits.point[a[h]], sc.pdf[a[h]], sc.is_specular[a[h]])
            add_emission(scene, result, a[h], att[h], obj[h], nh, prev, n_lights, True)
    return result
