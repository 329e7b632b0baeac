"""Batched integrators: the estimators of rtpy/integrators for many camera rays at once.

Each integrator maps camera rays (origins (N, 3), unit directions (N, 3)) to one
radiance sample per ray (N, 3), with the same estimator as its scalar twin:

- center / jittered: emission of an emitter's emitting face, else the flat colour
  (albedo), else the background;
- direct: emission + one bounce of direct light (light sampling, BRDF sampling,
  power-heuristic MIS); exactly "path" with max_depth = 2;
- whitted: direct light at non-specular hits, the material's deterministic rays
  (reflection R, refraction 1 - R) at specular hits, up to max_depth segments;
- path: next-event estimation + BRDF sampling with MIS, Russian roulette after
  segment `russian_roulette` (survival min(0.95, max(beta))), max_depth segments
  counting the camera ray; nee = false samples only point lights; mis = false
  adds area lights by light sampling alone (weight 1, and weight 0 for emission
  found by BRDF sampling after a non-specular bounce).

Paths run as a wavefront: every live path is at the same segment, the whole
batch is intersected, shaded by material kind, and paths that end are dropped.
Work the scene does not need is skipped: no shadow rays without lights, no
(u, v) without image textures, no tangents without materials that use them.
Random numbers come from the numpy Generator passed in, never a global one.
"""

from __future__ import annotations

import numpy as np

from ..render_settings import RenderSettings
from ..scene import Scene
from ..texture import CheckerTexture, SolidColor
from .arrays import add_rows, divide, put_rows, scale
from .arrays import rows as rows_of
from .geometry import Geometry, max3, offset_scale, spawn_origins
from .hits import HitBatch
from .lights import LightTable
from .materials import MaterialTable
from .materials.fallback import ScalarFallback
from .materials.simple import SIMPLE_KERNELS

# Whitted's specular rays branch; batches are processed depth first in chunks of
# at most this many rays, so memory stays bounded however deep the recursion goes.
WHITTED_CHUNK = 8192


def power_heuristic(pdf_a: np.ndarray, pdf_b: np.ndarray) -> np.ndarray:
    """Veach's power heuristic (beta = 2), 0 where both densities vanish."""
    a2 = pdf_a * pdf_a
    total = a2 + pdf_b * pdf_b
    with np.errstate(divide="ignore", invalid="ignore"):
        return np.where(total > 0.0, a2 / total, 0.0)


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[:, 0] * b[:, 0] + a[:, 1] * b[:, 1] + a[:, 2] * b[:, 2]


def _needs(materials: MaterialTable) -> tuple[bool, bool]:
    """(need_uv, need_tangent): whether any material can read a hit's (u, v) or its
    tangent. Only textures that are not solid colours or checkers read (u, v);
    only materials with a shading frame (all but the simple ones) read tangents;
    a material without a batched twin may read anything."""
    simple = set(SIMPLE_KERNELS.values())
    need_uv = need_tangent = False
    for kernel in materials.kernels:
        if isinstance(kernel, ScalarFallback):
            return True, True
        if type(kernel) not in simple:
            need_tangent = True
        for m in kernel.materials:
            albedo = getattr(m, "albedo", None)
            if albedo is not None and type(albedo) not in (SolidColor, CheckerTexture):
                need_uv = True
    return need_uv, need_tangent


class Tracer:
    """A scene prepared for batched rendering: geometry, materials, lights and what
    rays see when they escape."""

    def __init__(self, scene: Scene) -> None:
        self.scene = scene
        self.geometry = Geometry(scene.objects)
        self.materials = MaterialTable(self.geometry.materials)
        self.need_uv, self.need_tangent = _needs(self.materials)
        self.lights = LightTable(
            scene, self.geometry, self.materials, self.need_uv, self.need_tangent
        )
        bg = scene.background
        self.background_color = np.array([bg.e0, bg.e1, bg.e2], dtype=np.float64)
        self.sky = bool(scene.sky)
        self.environment = getattr(scene, "environment", None)

    def background(self, d: np.ndarray) -> np.ndarray:
        """Radiance of rays escaping along d (N, 3): the constant background, or
        RTIOW's sky gradient by the direction's y component, or the scene's
        environment (rtpy.environment) when it has one."""
        if self.environment is not None:
            return self.environment.radiance_array(d)
        if not self.sky:
            return np.broadcast_to(self.background_color, d.shape)
        a = 0.5 * (d[:, 1] / np.sqrt(_dot(d, d)) + 1.0)
        return np.stack([1.0 - 0.5 * a, 1.0 - 0.3 * a, np.ones_like(a)], axis=1)

    def hits(self, obj, o, d, t) -> HitBatch:
        return self.geometry.hit_batch(obj, o, d, t, self.need_uv, self.need_tangent)

    def sample_one_light(
        self,
        hits: HitBatch,
        ids: np.ndarray,
        rng: np.random.Generator,
        include_area: bool,
        mis: bool = True,
    ) -> np.ndarray:
        """sample_one_light: the light-sampling estimate (N, 3) of light reflected
        toward hits.wo, from one light chosen uniformly, with a shadow ray; area
        lights are MIS-weighted against BRDF sampling (weight 1 if not mis)."""
        n = len(hits)
        out = np.zeros((n, 3))
        n_lights = self.lights.count(include_area)
        s = self.lights.sample(hits.point, rng, include_area)
        cos_i = _dot(hits.normal, s.direction)
        ok = s.valid & (max3(s.radiance) > 0.0) & (cos_i > 0.0)
        idx = np.flatnonzero(ok)
        if idx.size == 0:
            return out
        whole = idx.size == n
        part = hits if whole else hits.take(idx)
        wi = s.direction if whole else rows_of(s.direction, idx)
        f, brdf_pdf = self.materials.eval(ids if whole else ids.take(idx), part, wi)
        lit = max3(f) > 0.0
        if not lit.all():
            k = np.flatnonzero(lit)
            idx, wi, f, brdf_pdf = idx.take(k), rows_of(wi, k), rows_of(f, k), brdf_pdf.take(k)
            part = part.take(k)
        if idx.size == 0:
            return out
        origin = spawn_origins(part.point, part.normal, wi)
        # Stop the shadow ray just short of the light's surface, and let the light
        # itself not block it: the spawned origin is off the point the light was
        # sampled from, so the shadow ray can meet the light's surface a little
        # before `distance` (by far more than the offsets where it arrives at a
        # slant), and a convex light cannot hide its own sampled point.
        t_max = (
            s.distance.take(idx) - offset_scale(rows_of(s.point, idx)) - offset_scale(part.point)
        )
        blocked = self.geometry.occluded(origin, wi, t_max, skip=s.obj.take(idx))
        if blocked.any():
            k = np.flatnonzero(~blocked)
            idx, f, brdf_pdf = idx.take(k), rows_of(f, k), brdf_pdf.take(k)
        pdf = s.pdf.take(idx) / n_lights
        if mis:
            weight = np.where(s.delta.take(idx), 1.0, power_heuristic(pdf, brdf_pdf))
        else:
            weight = np.ones(idx.size)
        contrib = scale(f * rows_of(s.radiance, idx), cos_i.take(idx) * weight / pdf)
        put_rows(out, idx, contrib)
        return out

    def emission_weight(
        self,
        obj: np.ndarray,
        hits: HitBatch,
        prev_point: np.ndarray | None,
        prev_pdf: np.ndarray,
        prev_specular: np.ndarray,
        n_mis: int,
        mis: bool = True,
    ) -> np.ndarray:
        """MIS weight (N,) of emission found by BRDF sampling from prev_point; 1 after
        the camera, after a specular bounce, or when lights are not sampled; 0
        after other bounces if not mis (light sampling alone counts it)."""
        w = np.ones(len(obj))
        if n_mis == 0 or prev_point is None:
            return w
        if not mis:
            return prev_specular.astype(np.float64)
        m = np.flatnonzero(~prev_specular)
        if m.size == len(obj):
            light_pdf = self.lights.direction_pdf(obj, prev_point, hits.point, hits.normal)
            return power_heuristic(prev_pdf, light_pdf / n_mis)
        if m.size:
            light_pdf = self.lights.direction_pdf(
                obj.take(m),
                rows_of(prev_point, m),
                rows_of(hits.point, m),
                rows_of(hits.normal, m),
            )
            w[m] = power_heuristic(prev_pdf.take(m), light_pdf / n_mis)
        return w

    def add_emission(
        self, result, rows, beta, obj, ids, hits, prev_point, prev_pdf, prev_specular, n_mis, mis
    ) -> None:
        """result[rows] += beta * emitted * MIS weight at the hits on emitters."""
        em = self.materials.emitter.take(ids)
        if not em.any():
            return
        e = np.flatnonzero(em)
        if e.size == len(ids):
            emitted = self.materials.emitted(ids, hits)
            w = self.emission_weight(obj, hits, prev_point, prev_pdf, prev_specular, n_mis, mis)
            add_rows(result, rows, scale(beta * emitted, w))
            return
        part = hits.take(e)
        emitted = self.materials.emitted(ids.take(e), part)
        w = self.emission_weight(
            obj.take(e),
            part,
            None if prev_point is None else rows_of(prev_point, e),
            prev_pdf.take(e),
            prev_specular.take(e),
            n_mis,
            mis,
        )
        add_rows(result, rows.take(e), scale(rows_of(beta, e) * emitted, w))


# --------------------------------------------------------------------------------------
# Integrators


class BatchIntegrator:
    """radiance(tracer, o, d, rng) -> (N, 3) samples for camera rays."""

    name = "integrator"
    uses_center_ray = False

    def __init__(self, settings: RenderSettings | None = None) -> None:
        self.settings = settings or RenderSettings()

    def compute_scattering(
        self, tracer: Tracer, o: np.ndarray, d: np.ndarray, rng: np.random.Generator
    ) -> np.ndarray:
        raise NotImplementedError


class FlatIntegrator(BatchIntegrator):
    """center and jittered: the flat colour of the first hit."""

    name = "jittered"

    def compute_scattering(self, tracer, o, d, rng):
        out = np.empty((len(o), 3))
        obj, t = tracer.geometry.closest_hit(o, d)
        miss = obj < 0
        out[miss] = tracer.background(d[miss])
        h = np.flatnonzero(~miss)
        if h.size == 0:
            return out
        hits = tracer.hits(obj[h], o[h], d[h], t[h])
        ids = tracer.geometry.material_id[obj[h]]
        color = np.zeros((h.size, 3))
        flat = np.ones(h.size, dtype=bool)
        em = np.flatnonzero(tracer.materials.emitter[ids])
        if em.size:
            emitted = tracer.materials.emitted(ids[em], hits.take(em))
            glowing = max3(emitted) > 0.0  # not black (emission is >= 0)
            color[em[glowing]] = emitted[glowing]
            flat[em[glowing]] = False
        f = np.flatnonzero(flat)
        if f.size:
            part = hits if f.size == h.size else hits.take(f)
            color[f] = tracer.materials.flat_color(ids[f], part)
        out[h] = color
        return out


class CenterIntegrator(FlatIntegrator):
    name = "center"
    uses_center_ray = True


class PathIntegrator(BatchIntegrator):
    """Unbiased path tracing as rtpy.integrators.PathIntegrator (see the module doc)."""

    name = "path"

    def _limits(self) -> tuple[int, int, bool]:
        s = self.settings
        return s.max_depth, s.russian_roulette, s.nee

    def compute_scattering(self, tracer, o, d, rng):
        max_depth, rr_start, nee = self._limits()
        n = len(o)
        result = np.zeros((n, 3))
        n_lights = tracer.lights.count(include_area=nee)
        n_mis = n_lights if nee else 0  # lights that MIS weights account for
        mis = self.settings.mis
        geo, materials = tracer.geometry, tracer.materials
        rows = np.arange(n)  # the camera ray each live path belongs to
        beta = np.ones((n, 3))
        prev_point = None
        prev_pdf = np.zeros(n)
        prev_specular = np.ones(n, dtype=bool)
        segment = 1
        while rows.size:
            obj, t = geo.closest_hit(o, d)
            miss = obj < 0
            if miss.any():
                m = np.flatnonzero(miss)
                dm = rows_of(d, m)
                add_rows(result, rows[m], beta.take(m, axis=0) * tracer.background(dm))
                keep = np.flatnonzero(~miss)
                rows, obj, t = rows.take(keep), obj.take(keep), t.take(keep)
                o, d, beta = rows_of(o, keep), rows_of(d, keep), rows_of(beta, keep)
                prev_pdf, prev_specular = prev_pdf.take(keep), prev_specular.take(keep)
                if prev_point is not None:
                    prev_point = rows_of(prev_point, keep)
                if rows.size == 0:
                    break
            hits = tracer.hits(obj, o, d, t)
            ids = geo.material_id.take(obj)
            tracer.add_emission(
                result, rows, beta, obj, ids, hits, prev_point, prev_pdf, prev_specular, n_mis, mis
            )
            if segment >= max_depth:
                break
            inert = materials.inert.take(ids)
            if inert.any():  # paths end on lights that reflect nothing (no kernel split)
                k = np.flatnonzero(~inert)
                rows, ids, hits, beta = rows.take(k), ids.take(k), hits.take(k), rows_of(beta, k)
                if rows.size == 0:
                    break
            if n_lights:
                ns = np.flatnonzero(~materials.specular.take(ids))
                if ns.size == rows.size:
                    direct = tracer.sample_one_light(hits, ids, rng, nee, mis)
                    direct *= beta
                    add_rows(result, rows, direct)
                elif ns.size:
                    part = hits.take(ns)
                    direct = tracer.sample_one_light(part, ids.take(ns), rng, nee, mis)
                    direct *= rows_of(beta, ns)
                    add_rows(result, rows.take(ns), direct)
            sc = materials.sample(ids, hits, rng)
            beta = beta * sc.weight
            bmax = max3(beta)
            alive = sc.alive & (bmax > 0.0)
            roulette = bool(rr_start and segment >= rr_start)
            if roulette:
                survive = np.minimum(0.95, bmax)
                alive &= rng.random(rows.size) < survive
            a = np.flatnonzero(alive)
            if a.size == rows.size:  # nothing ended: no compaction
                point, normal, d = hits.point, hits.normal, sc.direction
                prev_pdf, prev_specular = sc.pdf, sc.specular
            else:
                rows, beta = rows.take(a), rows_of(beta, a)
                point, normal = rows_of(hits.point, a), rows_of(hits.normal, a)
                d = rows_of(sc.direction, a)
                prev_pdf, prev_specular = sc.pdf.take(a), sc.specular.take(a)
                if roulette:
                    survive = survive.take(a)
            if roulette:
                beta = divide(beta, survive)
            o = spawn_origins(point, normal, d)
            prev_point = point
            segment += 1
        return result


class DirectIntegrator(PathIntegrator):
    """Emission + one bounce of direct light: "path" with max_depth = 2, light
    sampling on, no Russian roulette."""

    name = "direct"

    def _limits(self):
        return 2, 0, True


class WhittedIntegrator(BatchIntegrator):
    """Whitted ray tracing as rtpy.integrators.WhittedIntegrator."""

    name = "whitted"

    def compute_scattering(self, tracer, o, d, rng):
        n = len(o)
        result = np.zeros((n, 3))
        max_depth = self.settings.max_depth
        # Depth-first over batches: (origins, directions, weights, rows, depth).
        stack = [(o, d, np.ones((n, 3)), np.arange(n), 1)]
        geo, materials = tracer.geometry, tracer.materials
        while stack:
            o, d, w, rows, depth = stack.pop()
            if len(rows) > WHITTED_CHUNK:
                for s in range(len(rows) - WHITTED_CHUNK, -WHITTED_CHUNK, -WHITTED_CHUNK):
                    sl = slice(max(s, 0), s + WHITTED_CHUNK)
                    stack.append((o[sl], d[sl], w[sl], rows[sl], depth))
                continue
            obj, t = geo.closest_hit(o, d)
            miss = obj < 0
            np.add.at(result, rows[miss], w[miss] * tracer.background(d[miss]))
            h = np.flatnonzero(~miss)
            if h.size == 0:
                continue
            o, d, w, rows, obj, t = o[h], d[h], w[h], rows[h], obj[h], t[h]
            hits = tracer.hits(obj, o, d, t)
            ids = geo.material_id[obj]
            em = np.flatnonzero(materials.emitter[ids])
            if em.size:
                emitted = materials.emitted(ids[em], hits.take(em))
                np.add.at(result, rows[em], w[em] * emitted)
            if depth >= max_depth:
                continue
            spec = materials.specular[ids]
            ns = np.flatnonzero(~spec)
            if ns.size:
                part = hits if ns.size == len(ids) else hits.take(ns)
                direct = direct_lighting(tracer, part, ids[ns], rng)
                np.add.at(result, rows[ns], w[ns] * direct)
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
                children.append((origin, direction[k], w[sp[k]] * weight[k], rows[sp[k]]))
            if children:
                stack.append(
                    (
                        np.concatenate([c[0] for c in children]),
                        np.concatenate([c[1] for c in children]),
                        np.concatenate([c[2] for c in children]),
                        np.concatenate([c[3] for c in children]),
                        depth + 1,
                    )
                )
        return result


def direct_lighting(
    tracer: Tracer, hits: HitBatch, ids: np.ndarray, rng: np.random.Generator
) -> np.ndarray:
    """direct_lighting at non-specular hits: light sampling of all lights plus one
    BRDF-sampled ray that sees the background or an emitter (MIS-weighted)."""
    n = len(hits)
    n_lights = tracer.lights.n
    result = tracer.sample_one_light(hits, ids, rng, True) if n_lights else np.zeros((n, 3))
    sc = tracer.materials.sample(ids, hits, rng)
    a = np.flatnonzero(sc.alive)
    if a.size == 0:
        return result
    d = sc.direction[a]
    o = spawn_origins(hits.point[a], hits.normal[a], d)
    att = sc.weight[a]
    obj, t = tracer.geometry.closest_hit(o, d)
    miss = obj < 0
    result[a[miss]] += att[miss] * tracer.background(d[miss])
    h = np.flatnonzero(~miss)
    if h.size:
        nids = tracer.geometry.material_id[obj[h]]
        if tracer.materials.emitter[nids].any():
            nh = tracer.hits(obj[h], o[h], d[h], t[h])
            tracer.add_emission(
                result,
                a[h],
                att[h],
                obj[h],
                nids,
                nh,
                hits.point[a[h]],
                sc.pdf[a[h]],
                sc.specular[a[h]],
                n_lights,
                True,
            )
    return result


INTEGRATORS: dict[str, type[BatchIntegrator]] = {
    "center": CenterIntegrator,
    "jittered": FlatIntegrator,
    "direct": DirectIntegrator,
    "whitted": WhittedIntegrator,
    "path": PathIntegrator,
}


def make_integrator(settings: RenderSettings) -> BatchIntegrator:
    return INTEGRATORS[settings.integrator](settings)
