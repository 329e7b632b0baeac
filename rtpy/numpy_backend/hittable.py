"""PrimitiveSet: the batched twin of rtpy.hittable.Hittable, for all primitives of one kind.

The objects of a scene are split by kind into structure-of-arrays sets (sphere.py,
quad.py, triangle.py), each intersected against a whole batch of rays in a few numpy
calls; index k of a set is its k-th primitive (its "local index"). Shapes without a
batched twin (a student's Hittable subclass) go into a ScalarSet, which calls their
scalar methods one ray at a time.

Conventions are the scalar classes': rays are (N, 3) origins and unit directions,
hits have t in (t_min, t_max), `geometric` gives the geometric normal (the scene
turns it toward the arriving ray), (u, v) and tangents are the scalar surface_uv and
surface_tangent. A set with few primitives tests every ray against every primitive;
a set with many is culled by a BVH, and a brute-force set of planar primitives by
clusters (bvh.py).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ..hit_info import HitInfo
from ..hittable import MIN_LIGHT_DISTANCE2, Hittable, area_pdf
from ..ray import Ray
from ..vec3 import Vec3
from .arrays import at, axpy, dot, scale
from .bvh import BVH, Clusters
from .vec3 import rows_of, to_vec3

INF = math.inf
# Sets with more primitives than this are culled by a BVH; fewer are tested brute force.
BVH_THRESHOLD = 24
# Rays are intersected in chunks of PAIR_CHUNK // K rays (at least RAY_CHUNK), so
# (chunk, K) temporaries stay in cache while small sets still make few numpy calls.
RAY_CHUNK = 1024
PAIR_CHUNK = 18432


class PrimitiveSet:
    """Primitives of one kind. Subclasses give the intersection kernels (hit_t, and
    all_t where a faster all-pairs form exists) and the hit records.

    objects   the scalar objects (for fallbacks and tests); index = local index
    bvh       a BVH over the primitives, or None (brute force)
    clusters  for brute-force planar sets, Clusters culling groups of primitives, or None
    """

    objects: list[Hittable]
    bvh: BVH | None = None
    clusters: Clusters | None = None
    # sample_light accepts one int k for all rows (no per-row gathers of the shape)
    one_index_lights = False

    def __len__(self) -> int:
        return len(self.objects)

    # --- intersection ----------------------------------------------------------
    def hit_t(self, o, d, k, t_min, t_max) -> np.ndarray:
        """Hittable.hit_t for (ray, primitive k) pairs: arrays broadcast; inf where missed."""
        raise NotImplementedError

    def all_t(
        self, o: np.ndarray, d: np.ndarray, t_min: float, t_max: np.ndarray | None = None
    ) -> np.ndarray:
        """(N, K) ray parameters of every ray against every primitive with t > t_min
        (inf: miss). The caller compares the smallest with each ray's t_max; a set may
        use t_max (N,), when given, to skip pairs that cannot hit before it."""
        k = np.arange(len(self))[None, :]
        return self.hit_t(o[:, None, :], d[:, None, :], k, t_min, INF)

    def pair_t(
        self,
        o: np.ndarray,
        d: np.ndarray,
        t_min: float,
        t_max: np.ndarray | None = None,
        columns: tuple[np.ndarray, np.ndarray] | None = None,
    ) -> np.ndarray | None:
        """all_t as (K, N), primitive by ray; a set may compute it in this layout, in
        which numpy runs the per-pair arithmetic and the reduction over primitives
        on contiguous rows (then all_t is its transpose). With t_max, None where the
        set finds that no pair can hit before it. columns: ray.ray_columns(o, d), when
        the caller has them (a set may use them instead of o and d)."""
        return self.all_t(o, d, t_min, t_max).T

    def bounding_boxes(self) -> tuple[np.ndarray, np.ndarray]:
        """(lo, hi), each (K, 3): the primitives' axis-aligned boxes (Hittable.bounding_box)."""
        raise NotImplementedError

    def corners(self) -> np.ndarray:
        """(K, C, 3) corners of planar primitives (for clustering)."""
        raise NotImplementedError

    def build_bvh(self) -> None:
        if len(self) > BVH_THRESHOLD:
            self.bvh = BVH(*self.bounding_boxes())

    def closest_hit(
        self,
        o: np.ndarray,
        d: np.ndarray,
        t_min: float,
        t_max: np.ndarray,
        any_hit: bool = False,
        ignore: np.ndarray | None = None,
        columns: tuple[np.ndarray, np.ndarray] | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """(t, local index) of each ray's closest hit before t_max (t_max, -1 if none),
        as the scalar BVH.closest_hit. any_hit: any hit will do (occlusion, BVH.any_hit).
        ignore: per ray, a primitive not to test (-1: none). columns: as in pair_t."""
        if self.bvh is not None:

            def test(r, p, tm):
                t = self.hit_t(o.take(r, axis=0), d.take(r, axis=0), p, t_min, tm)
                if ignore is not None:
                    t[p == ignore.take(r)] = INF
                return t

            return self.bvh.traverse(o, d, t_min, t_max, test, any_hit)
        if self.clusters is not None:
            return self.clusters.closest_hit(o, d, t_min, t_max, any_hit, ignore)
        t_best = np.array(t_max, dtype=np.float64, copy=True)
        idx = np.full(len(o), -1, dtype=np.int64)
        chunk = max(RAY_CHUNK, PAIR_CHUNK // len(self))
        for s in range(0, len(o), chunk):
            e = min(s + chunk, len(o))
            cols = None if columns is None else (columns[0][:, s:e], columns[1][:, s:e])
            t = self.pair_t(o[s:e], d[s:e], t_min, t_best[s:e] if any_hit else None, cols)
            if t is None:
                continue
            if ignore is not None:
                r = np.flatnonzero(ignore[s:e] >= 0)
                t[ignore[s:e][r], r] = INF
            tj, j = nearest(t)
            hit = tj < t_best[s:e]
            np.copyto(t_best[s:e], tj, where=hit)
            np.copyto(idx[s:e], j, where=hit)
        return t_best, idx

    # --- hit records -------------------------------------------------------------
    def geometric(self, k, o, d, t) -> tuple[np.ndarray, np.ndarray]:
        """(point, geometric unit normal) of hits on primitives k along rays at t: the
        parts of Hittable.hit_info the scene needs to build a HitBatch."""
        raise NotImplementedError

    def surface_uv(self, k, point) -> tuple[np.ndarray, np.ndarray]:
        raise NotImplementedError

    def shading_normal(self, k, point, geo) -> np.ndarray:
        """The unit normals materials shade with at hits `point` on primitives k, on
        the side of the geometric normals geo: geo itself, except on triangles with
        vertex normals (rtpy.mesh.SmoothTriangle)."""
        return geo

    def surface_tangent(self, k, point) -> tuple[np.ndarray, np.ndarray]:
        """(tangent (N, 3), valid (N,) bool): Hittable.surface_tangent; invalid where it
        returns None (then HitInfo falls back to ONB(normal).u)."""
        raise NotImplementedError

    # --- as area lights ------------------------------------------------------------
    def area(self, k) -> np.ndarray:
        raise NotImplementedError

    def sample_point(self, k, r1, r2) -> tuple[np.ndarray, np.ndarray]:
        """Hittable.sample_point: (points (N, 3), geometric unit normals) uniform by area."""
        raise NotImplementedError

    def sample_direction(self, k, p, r1, r2):
        """Hittable.sample_direction: (direction, pdf, valid) toward a point sampled
        uniformly by area, pdf converted to solid angle."""
        q, n = self.sample_point(k, r1, r2)
        return area_direction(p, q, n, self.area(k))[:3]

    def direction_pdf(self, k, p, q, n) -> np.ndarray:
        """Hittable.direction_pdf: the density with which sample_direction(p) picks the
        direction toward the points q (normals n) on primitives k."""
        return area_direction_pdf(p, q, n, self.area(k))

    def sample_light(self, k, p, r1, r2):
        """AreaLight.sample's geometry: (direction, pdf, valid, t, point, geometric
        normal): sample_direction, traced from p itself (not offset) to the shape."""
        direction, pdf, valid = self.sample_direction(k, p, r1, r2)
        t = self.hit_t(p, direction, k, 0.0, INF)
        valid &= t < INF
        point, geo = self.geometric(k, p, direction, np.where(valid, t, 0.0))
        return direction, pdf, valid, t, point, geo


def nearest(t: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """(t.min(axis=0), t.argmin(axis=0)) for (K, N) t: each ray's smallest t and the
    first primitive giving it. numpy reduces along a C-contiguous array's first axis
    quickly, but finds the argmin row by row, slowly for small K: here the argmin of
    a C-contiguous t is the smallest k - K over the rows equal to the minimum."""
    k = len(t)
    if not t.flags.c_contiguous or k > 127:  # (all_t's (N, K) transposed: rows are cheap)
        j = t.argmin(axis=0)
        return t.T.ravel().take(j + np.arange(0, t.size, k)), j
    tj = t.min(axis=0)
    code = (t == tj).view(np.int8)
    code *= np.arange(-k, 0, dtype=np.int8)[:, None]
    j = code.min(axis=0).astype(np.int64)
    j += k
    return tj, j


def area_direction(
    p: np.ndarray, point: np.ndarray, normal: np.ndarray, area: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """Hittable.sample_direction after sample_point: (direction, pdf, valid, distance)
    for the direction from p to a point sampled by area, pdf = dist^2 / (|cos_light| area)."""
    dv = point - p
    dist2 = dot(dv, dv)
    valid = dist2 >= MIN_LIGHT_DISTANCE2
    # Invalid rows (too near, grazing) may divide by ~0 here; np.where discards them.
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        dist = np.sqrt(dist2)
        direction = scale(dv, 1.0 / dist)
        cos_light = np.abs(dot(direction, normal))
        valid &= cos_light >= 1e-12
        pdf = area_pdf(dist2, cos_light, area)
    return direction, np.where(valid, pdf, 0.0), valid, dist


def area_direction_pdf(p: np.ndarray, q: np.ndarray, n: np.ndarray, area: np.ndarray) -> np.ndarray:
    """Hittable.direction_pdf: solid-angle density at p of area sampling picking q
    (normal n, either side)."""
    dv = q - p
    dist2 = dot(dv, dv)
    # Grazing or coincident points divide by ~0 here; np.where below discards them.
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        cos_light = np.abs(dot(dv, n)) / np.sqrt(dist2)
        pdf = area_pdf(dist2, cos_light, area)
    return np.where((dist2 < MIN_LIGHT_DISTANCE2) | ~(cos_light >= 1e-12), 0.0, pdf)


class PlanarSet(PrimitiveSet):
    """Quads and triangles: a plane with unit normal `normal`, a constant tangent and
    corners; clustered when brute force (see bvh.Clusters)."""

    one_index_lights = True

    def __init__(self, shapes: Sequence[Hittable]) -> None:
        self.objects = list(shapes)
        self.normal = rows_of(s.normal for s in shapes)
        self.tan = rows_of(s._tangent for s in shapes)  # unit tangent (along u)
        self._area = np.array([float(s.area()) for s in shapes], dtype=np.float64)

    def build_culling(self, cluster: bool) -> None:
        """A BVH for many primitives, else (if `cluster`) clusters where they cull."""
        self.build_bvh()
        if cluster and self.bvh is None:
            self.clusters = Clusters.build(self)

    def bounding_boxes(self):
        corners = self.corners()
        return corners.min(axis=1), corners.max(axis=1)

    def surface_tangent(self, k, point):
        return self.tan[k], np.ones(len(k), dtype=bool)

    def area(self, k):
        return at(self._area, k)

    def geometric(self, k, o, d, t):
        return axpy(t, d, o), self.normal.take(k, axis=0)

    def sample_light(self, k, p, r1, r2):
        """AreaLight.sample's geometry: (direction, pdf, valid, t, point, geometric
        normal). The sampled point is where the ray from p along the direction meets
        the plane, so it is not traced again (the scalar code traces it and gets the
        same point up to rounding)."""
        q, n = self.sample_point(k, r1, r2)
        direction, pdf, valid, dist = area_direction(p, q, n, self.area(k))
        return direction, pdf, valid, dist, q, n


class ScalarSet(PrimitiveSet):
    """Shapes without a batched twin, intersected by their scalar methods per ray."""

    def __init__(self, objects: Sequence[Hittable]) -> None:
        self.objects = list(objects)

    def _rays(self, o, d):
        return [Ray(to_vec3(oi), to_vec3(di)) for oi, di in zip(o, d, strict=True)]

    def closest_hit(self, o, d, t_min, t_max, any_hit=False, ignore=None):
        t_best = np.array(t_max, dtype=np.float64, copy=True)
        idx = np.full(len(o), -1, dtype=np.int64)
        for i, ray in enumerate(self._rays(o, d)):
            for j, obj in enumerate(self.objects):
                if ignore is not None and ignore[i] == j:
                    continue
                t = obj.hit_t(ray, t_min, float(t_best[i]))
                if t is not None:
                    t_best[i], idx[i] = t, j
                    if any_hit:
                        break
        return t_best, idx

    def hit_t(self, o, d, k, t_min, t_max):
        o, d = np.broadcast_arrays(o, d)
        k, t_max = np.broadcast_to(k, o.shape[:-1]), np.broadcast_to(t_max, o.shape[:-1])
        out = np.full(o.shape[:-1], INF)
        for i in np.ndindex(out.shape):
            ray = Ray(to_vec3(o[i]), to_vec3(d[i]))
            t = self.objects[int(k[i])].hit_t(ray, t_min, float(t_max[i]))
            out[i] = INF if t is None else t
        return out

    def geometric(self, k, o, d, t):
        infos = [
            self.objects[int(ki)].hit_info(ray, float(ti))
            for ki, ray, ti in zip(k, self._rays(o, d), t, strict=True)
        ]
        p = rows_of(h.point for h in infos)
        n = rows_of(h.normal for h in infos)
        # Back to the geometric side: HitInfo's normal faces the ray.
        flip = np.array([not h.front_face for h in infos], dtype=bool)
        n[flip] *= -1.0
        return p, n

    @staticmethod
    def _hit(point) -> HitInfo:
        return HitInfo(to_vec3(point), Vec3(0.0, 0.0, 1.0), 0.0, True, None, None)

    def surface_uv(self, k, point):
        pairs = zip(k, point, strict=True)
        uv = [self.objects[int(ki)].surface_uv(self._hit(p)) for ki, p in pairs]
        uv = np.array(uv, dtype=np.float64).reshape(-1, 2)
        return uv[:, 0], uv[:, 1]

    def surface_tangent(self, k, point):
        tan = np.zeros((len(k), 3))
        valid = np.zeros(len(k), dtype=bool)
        for i, (ki, p) in enumerate(zip(k, point, strict=True)):
            s = self.objects[int(ki)].surface_tangent(self._hit(p))
            if s is not None:
                tan[i], valid[i] = (float(s.e0), float(s.e1), float(s.e2)), True
        return tan, valid

    def area(self, k):
        return np.array([self.objects[int(ki)].area() for ki in k], dtype=np.float64)

    def sample_direction(self, k, p, r1, r2):
        direction = np.zeros((len(k), 3))
        pdf = np.zeros(len(k))
        valid = np.zeros(len(k), dtype=bool)
        for i in range(len(k)):
            s = self.objects[int(k[i])].sample_direction(to_vec3(p[i]), float(r1[i]), float(r2[i]))
            if s is not None:
                direction[i], pdf[i], valid[i] = (s[0].e0, s[0].e1, s[0].e2), s[1], True
        return direction, pdf, valid

    def direction_pdf(self, k, p, q, n):
        out = np.zeros(len(k))
        for i in range(len(k)):
            hit = HitInfo(to_vec3(q[i]), to_vec3(n[i]), 0.0, True, None)
            out[i] = self.objects[int(k[i])].direction_pdf(to_vec3(p[i]), hit)
        return out
