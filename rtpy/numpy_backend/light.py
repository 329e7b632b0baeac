"""LightTable: the lights of a scene sampled for many points at once, the twin of
rtpy/light.py (and of the shapes' sample_direction, through their primitive sets).

A light sample from a receiving point p gives the unit direction wi toward the
light, the distance to the point on the light, the radiance arriving along wi,
its solid-angle pdf and whether the light is a delta light:

- a point light: the one direction, pdf 1, radiance I / d^2 (falls off as 1/r^2);
- an area light (an object whose material emits): a direction from the shape's
  sample_direction (spheres seen from outside by the cone they subtend, else
  uniformly by area with pdf = pdf_area * d^2 / |cos theta_light|), traced to the
  shape itself from p to find the point and its emission (AreaLight.sample).

Lights are chosen uniformly (index min(int(u n), n - 1)); the pdf returned does
not include the 1 / n of that choice.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..hittable import MIN_LIGHT_DISTANCE2
from .arrays import dot, put_rows, rows
from .materials.diffuse_light import DiffuseLightKernel
from .vec3 import rows_of

if TYPE_CHECKING:
    from .scene import BatchScene


@dataclass
class LightSamples:
    """N light samples; where `valid` is False the sample contributes nothing."""

    direction: np.ndarray  # (N, 3) unit, from the receiving point toward the light
    distance: np.ndarray  # (N,)
    radiance: np.ndarray  # (N, 3)
    pdf: np.ndarray  # (N,) solid-angle density (1 for point lights)
    is_delta: np.ndarray  # (N,) bool: point light
    point: np.ndarray  # (N, 3) the point on the light
    valid: np.ndarray  # (N,) bool
    obj: np.ndarray | None = None  # (N,) the area light's object index, -1 for point lights


class LightTable:
    """The lights of a scene: point lights first, then area lights in object order
    (Scene.lights' order). Area lights are objects of the BatchScene; their emission
    comes from its MaterialTable.
    """

    def __init__(self, scene: BatchScene) -> None:
        self.scene = scene
        point_lights = scene.scene.point_lights
        self.point_position = rows_of(p.position for p in point_lights)
        self.point_intensity = rows_of(p.intensity for p in point_lights)
        index = {id(obj): int(scene.first[i]) for i, obj in enumerate(scene.objects)}
        area = [index[id(a.shape)] for a in scene.scene.area_lights]
        self.area_object = np.array(area, dtype=np.int64)
        self.n_point = len(point_lights)
        self.n_area = len(self.area_object)
        self.n = self.n_point + self.n_area
        self.single = self._single_diffuse_light()

    def _single_diffuse_light(self):
        """(set, local index, object, (2, 3) rows [0, emit], two_sided) when the scene's
        only light is one area light whose material is a DiffuseLight (all bundled
        scenes with an area light), else None. Such a light is sampled by sample_single."""
        if self.n != 1 or self.n_area != 1:
            return None
        scene, obj = self.scene, int(self.area_object[0])
        materials = scene.materials
        mid = int(scene.material_id[obj])
        kernel = materials.kernels[materials.kind[mid]]
        if not isinstance(kernel, DiffuseLightKernel):
            return None
        slot = materials.slot[mid]
        prims = scene.sets[scene.kind[obj]]
        dark_or_emit = np.stack([np.zeros(3), kernel.emit[slot]])
        return prims, int(scene.local[obj]), obj, dark_or_emit, bool(kernel.two_sided[slot])

    def count(self, include_area: bool = True) -> int:
        return self.n if include_area else self.n_point

    def sample(
        self, p: np.ndarray, rng: np.random.Generator, include_area: bool = True
    ) -> LightSamples:
        """One light sample per receiving point p (N, 3): a light chosen uniformly
        among all lights (or only the point lights), then a direction toward it."""
        n = len(p)
        n_lights = self.count(include_area)
        if self.single is not None and include_area:
            return self.sample_single(p, rng)
        u = rng.random(n)
        choice = np.minimum((u * n_lights).astype(np.int64), n_lights - 1)
        return self.sample_chosen(p, choice, rng)

    def sample_chosen(
        self, p: np.ndarray, choice: np.ndarray, rng: np.random.Generator
    ) -> LightSamples:
        """One light sample per receiving point p (N, 3) from the light choice (N,)
        (an index into the lights: point lights first), a direction toward it."""
        n = len(p)
        out = LightSamples(
            np.zeros((n, 3)),
            np.zeros(n),
            np.zeros((n, 3)),
            np.zeros(n),
            choice < self.n_point,
            np.zeros((n, 3)),
            np.zeros(n, dtype=bool),
            np.full(n, -1, dtype=np.int64),
        )
        pt = np.flatnonzero(out.is_delta)
        if pt.size:
            self._sample_point_lights(p, choice, pt, out)
        if pt.size == n:
            return out
        r = rng.random((2, n - pt.size))
        if pt.size == 0:  # area lights only: no gathers
            obj = self.area_object.take(choice - self.n_point)
            self.sample_area(p, obj, r[0], r[1], out, slice(None))
        else:
            ar = np.flatnonzero(~out.is_delta)
            obj = self.area_object.take(choice.take(ar) - self.n_point)
            self.sample_area(rows(p, ar), obj, r[0], r[1], out, ar)
        return out

    def sample_single(self, p: np.ndarray, rng: np.random.Generator) -> LightSamples:
        """sample() for a single DiffuseLight area light: no light choice, and the
        emission is `emit` where the sample sees the light's front face (or both faces
        when two-sided), without building the hits on the light."""
        prims, local, obj, dark_or_emit, two_sided = self.single
        n = len(p)
        rng.random(n)  # the light choice's number: the general path's random stream
        r = rng.random((2, n))
        k = int(local) if prims.one_index_lights else np.full(n, local, dtype=np.int64)
        direction, pdf, valid, t, point, geo = prims.sample_light(k, p, r[0], r[1])
        valid &= pdf > 0.0
        # The front face is the one the geometric normal points to: dot(geo, d) < 0
        # for the direction d arriving there, as in BatchScene.hits_at.
        on = valid if two_sided else valid & (dot(geo, direction) < 0.0)
        radiance = dark_or_emit.take(on.view(np.uint8), axis=0)  # emit where on, else 0
        is_delta = np.zeros(n, dtype=bool)
        return LightSamples(
            direction, t, radiance, pdf, is_delta, point, valid, np.full(n, obj, dtype=np.int64)
        )

    # Twin kept: PointLight.sample is the week-5 exercise, in Vec3 form.
    def _sample_point_lights(self, p, choice, idx, out: LightSamples) -> None:
        q = self.point_position[choice[idx]]
        dv = q - p[idx]
        dist2 = dot(dv, dv)
        ok = dist2 >= MIN_LIGHT_DISTANCE2
        # Rows too near the light divide by 1 instead of ~0: they stay invalid, with
        # finite numbers (NaN or inf there would spread through the masked arithmetic).
        safe2 = np.where(ok, dist2, 1.0)
        out.direction[idx] = dv / np.sqrt(safe2)[:, None]
        out.radiance[idx] = self.point_intensity[choice[idx]] * (1.0 / safe2)[:, None]
        out.distance[idx] = np.sqrt(dist2)
        out.pdf[idx] = 1.0
        out.point[idx] = q
        out.valid[idx] = ok

    def sample_area(
        self,
        p: np.ndarray,
        obj: np.ndarray,
        r1: np.ndarray,
        r2: np.ndarray,
        out: LightSamples,
        idx: np.ndarray,
    ) -> None:
        """AreaLight.sample for points p toward objects obj with uniforms r1, r2;
        writes rows idx of out."""
        scene = self.scene
        if out.obj is not None:
            out.obj[idx] = obj
        groups = scene.set_of(obj)
        if len(groups) == 1:
            prims, local, _ = groups[0]
            direction, pdf, valid, t, point, geo = prims.sample_light(local, p, r1, r2)
        else:
            n = len(p)
            direction, point, geo = np.zeros((n, 3)), np.zeros((n, 3)), np.zeros((n, 3))
            pdf, t = np.zeros(n), np.zeros(n)
            valid = np.zeros(n, dtype=bool)
            for prims, local, i in groups:
                direction[i], pdf[i], valid[i], t[i], point[i], geo[i] = prims.sample_light(
                    local, p[i], r1[i], r2[i]
                )
        valid &= pdf > 0.0
        ok = np.flatnonzero(valid)
        out.valid[idx] = valid
        if ok.size == 0:
            return
        if ok.size < len(p):
            obj, t, pdf = obj.take(ok), t.take(ok), pdf.take(ok)
            direction, point, geo = rows(direction, ok), rows(point, ok), rows(geo, ok)
        hits = scene.hits_at(obj, point, geo, direction, t)
        radiance = scene.materials.emitting(scene.material_id.take(obj), hits)
        if isinstance(idx, slice) and ok.size == len(p):  # every row: no scatter
            out.direction, out.distance, out.radiance = direction, t, radiance
            out.pdf, out.point = pdf, point
            return
        j = np.arange(len(out.pdf))[idx].take(ok)
        put_rows(out.direction, j, direction)
        out.distance[j] = t
        put_rows(out.radiance, j, radiance)
        out.pdf[j] = pdf
        put_rows(out.point, j, point)

    def direction_pdf(self, obj: np.ndarray, p: np.ndarray, q: np.ndarray, n: np.ndarray):
        """AreaLight.pdf: solid-angle density of sampling the direction from p to the
        point q (normal n, either side) on the emitting objects obj."""
        out = np.zeros(len(obj))
        for prims, local, i in self.scene.set_of(obj):
            out[i] = prims.direction_pdf(local, p[i], q[i], n[i])
        return out
