"""Scene geometry as arrays: closest hits and occlusion for many rays at once.

The objects of a scene are split by kind into structure-of-arrays sets (spheres,
quads, triangles), each intersected against a whole batch of rays in a few numpy
calls. A set with few primitives tests every ray against every primitive (an
(N, K) array of ray parameters); a set with many builds a bounding volume
hierarchy (binned SAH over axis-aligned boxes) and traverses it for all rays at
once, level by level, so a scene with hundreds of spheres costs only the boxes
and spheres each ray comes near. Shapes rtpy does not know (a student's
Hittable subclass) are intersected by their scalar methods, one ray at a time.

Conventions are the scalar classes' (rtpy/sphere.py, quad.py, triangle.py):
rays are (N, 3) origins and unit directions, hits have t in (t_min, t_max),
normals of a HitBatch face the arriving ray, `front_face` says whether that is
the geometric outside, (u, v) and tangents are the scalar surface_uv and
HitInfo.tangent. Spheres use the scalar's cancellation-free root formula, op for
op, so their t is bit-identical; quads and triangles use an algebraically equal
form that turns the work into small matrix products (t agrees to ~1e-15).
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

from ..hit_info import HitInfo
from ..hittable import Hittable
from ..quad import Quad
from ..ray import SPAWN_ABSOLUTE_OFFSET, SPAWN_RELATIVE_OFFSET, Ray
from ..sphere import Sphere
from ..triangle import Triangle
from ..vec3 import Vec3
from .arrays import at, axpy, put_rows, rows, scale
from .hits import HitBatch, unused
from .materials.frame import local_to_world
from .trig import cos_sin_2pi

# Sets with more primitives than this are culled by a BVH; fewer are tested brute force.
BVH_THRESHOLD = 24
BVH_LEAF_SIZE = 4
# Rays are intersected in chunks of PAIR_CHUNK // K rays (at least RAY_CHUNK), so
# (chunk, K) temporaries stay in cache while small sets still make few numpy calls.
RAY_CHUNK = 1024
PAIR_CHUNK = 18432
# Brute-force spheres take rays in chunks of this many (the cheap test's (K, chunk)
# temporaries stay near the cache while the numpy calls stay few): on week08_three_balls
# 16,384 was ~5 % faster than 8,192 or 65,536 and 1.4x faster than 2,048.
SPHERE_CHUNK = 16384
# A brute-force set of planar primitives culls clusters of them by their bounding box
# (see cluster_parts): clusters of at least CLUSTER_SIZE primitives whose box has at
# most CLUSTER_AREA of the surface area of the whole set's box.
CLUSTER_SIZE = 3
CLUSTER_AREA = 0.5

INF = math.inf
# Quads accept hits this little outside their edges (in units of the edge length):
# rounding differs from the scalar formula's, and without the margin a ray exactly
# along the shared edge of two quads (a corner of a closed box) could slip between.
EDGE_A = 1e-9
EDGE = 1.0 + 2.0 * EDGE_A  # the same margin for |2a - 1| <= 1


def _v(v: Vec3) -> list[float]:
    return [float(v.e0), float(v.e1), float(v.e2)]


def max3(a: np.ndarray) -> np.ndarray:
    """Largest of the three components of (N, 3) a: a.max(axis=1), but a reduction over
    an axis of length 3 is several times slower than two elementwise maxima."""
    return np.maximum(np.maximum(a[:, 0], a[:, 1]), a[:, 2])


def onb_u(w: np.ndarray) -> np.ndarray:
    """First axis of the scalar ONB(w) (Duff et al. 2017) for (N, 3) unit vectors w."""
    w0, w1, w2 = w[:, 0], w[:, 1], w[:, 2]
    sign = np.copysign(1.0, w2)
    a = -1.0 / (sign + w2)
    b = w0 * w1 * a
    return np.stack([1.0 + sign * w0 * w0 * a, sign * b, -sign * w0], axis=1)


def offset_scale(p: np.ndarray) -> np.ndarray:
    """rtpy.ray.offset_scale for (N, 3) points: how far a spawned ray starts off p."""
    a = np.abs(p)
    return SPAWN_ABSOLUTE_OFFSET + SPAWN_RELATIVE_OFFSET * max3(a)


def spawn_origins(point: np.ndarray, normal: np.ndarray, direction: np.ndarray) -> np.ndarray:
    """Origins of rtpy.ray.spawn_ray(point, normal, direction) for (N, 3) arrays: the
    point pushed off the surface along the normal to the side the direction goes."""
    eps = offset_scale(point)
    below = _dot(direction, normal) < 0.0
    np.negative(eps, out=eps, where=below)
    return axpy(eps, normal, point)


# --------------------------------------------------------------------------------------
# Bounding volume hierarchy over the primitives of one set


class BVH:
    """A binary BVH over K axis-aligned boxes (binned SAH), stored as arrays.

    Node i has box lo[i], hi[i]; an inner node has children left[i], right[i]; a
    leaf (count[i] > 0) holds primitives order[start[i] : start[i] + count[i]].
    """

    def __init__(self, lo: np.ndarray, hi: np.ndarray, leaf_size: int = BVH_LEAF_SIZE) -> None:
        k = len(lo)
        centroid = 0.5 * (lo + hi)
        nodes_lo, nodes_hi, left, right, start, count = [], [], [], [], [], []
        order: list[int] = []

        def build(idx: np.ndarray) -> int:
            node = len(nodes_lo)
            nodes_lo.append(lo[idx].min(axis=0))
            nodes_hi.append(hi[idx].max(axis=0))
            left.append(-1)
            right.append(-1)
            start.append(0)
            count.append(0)
            split = None if len(idx) <= leaf_size else self._sah_split(idx, lo, hi, centroid)
            if split is None:
                start[node] = len(order)
                count[node] = len(idx)
                order.extend(idx.tolist())
                return node
            a, b = split
            left[node] = build(a)
            right[node] = build(b)
            return node

        build(np.arange(k))
        self.lo = np.array(nodes_lo)
        self.hi = np.array(nodes_hi)
        self.left = np.array(left, dtype=np.int64)
        self.right = np.array(right, dtype=np.int64)
        self.start = np.array(start, dtype=np.int64)
        self.count = np.array(count, dtype=np.int64)
        self.order = np.array(order, dtype=np.int64)

    @staticmethod
    def _sah_split(idx, lo, hi, centroid, bins: int = 16):
        """Split idx in two by the cheapest of `bins` planes per axis (surface area
        heuristic), or None when keeping a leaf is cheaper."""

        def area(a, b):
            e = np.maximum(b - a, 0.0)
            return 2.0 * (e[..., 0] * e[..., 1] + e[..., 1] * e[..., 2] + e[..., 2] * e[..., 0])

        c = centroid[idx]
        best = (area(lo[idx].min(0), hi[idx].max(0)) * len(idx), None)
        for axis in range(3):
            cmin, cmax = c[:, axis].min(), c[:, axis].max()
            if not cmax > cmin:
                continue
            b = np.minimum(((c[:, axis] - cmin) / (cmax - cmin) * bins).astype(int), bins - 1)
            for plane in range(1, bins):
                m = b < plane
                n_left = int(m.sum())
                if n_left == 0 or n_left == len(idx):
                    continue
                il, ir = idx[m], idx[~m]
                cost = area(lo[il].min(0), hi[il].max(0)) * len(il) + area(
                    lo[ir].min(0), hi[ir].max(0)
                ) * len(ir)
                if cost < best[0]:
                    best = (cost, (il, ir))
        if best[1] is None and len(idx) > 4 * BVH_LEAF_SIZE:
            # All centroids together (or no better split): halve by index.
            half = len(idx) // 2
            return idx[:half], idx[half:]
        return best[1]

    def traverse(
        self,
        o: np.ndarray,
        d: np.ndarray,
        t_min: float,
        t_max: np.ndarray,
        test: Callable[[np.ndarray, np.ndarray, np.ndarray], np.ndarray],
        any_hit: bool = False,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Closest (or any) hit of every ray among the primitives.

        test(ray_index, prim_index, t_max_pairs) -> t of each (ray, primitive) pair
        (inf for a miss). Returns (t, prim) per ray: t_max and -1 where nothing is
        hit before t_max. All rays descend the tree together, one level per
        iteration; leaves found at a level are tested at once and shrink the rays'
        t_max, which prunes the boxes of later levels.
        """
        n = len(o)
        best_t = np.array(t_max, dtype=np.float64, copy=True)
        best_p = np.full(n, -1, dtype=np.int64)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            safe = np.where(np.abs(d) < 1e-300, np.copysign(1e-300, d), d)
            inv = 1.0 / safe
        ray = np.arange(n)
        node = np.zeros(n, dtype=np.int64)
        done = np.zeros(n, dtype=bool)
        while ray.size:
            ro, ri = o[ray], inv[ray]
            with np.errstate(invalid="ignore", over="ignore"):
                t0 = (self.lo[node] - ro) * ri
                t1 = (self.hi[node] - ro) * ri
            near = max3(np.minimum(t0, t1))
            lo = np.maximum(t0, t1)
            far = np.minimum(np.minimum(lo[:, 0], lo[:, 1]), lo[:, 2])
            keep = (near <= far) & (far > t_min) & (near < best_t[ray])
            if any_hit:
                keep &= ~done[ray]
            ray, node = ray[keep], node[keep]
            leaf = self.count[node] > 0
            if leaf.any():
                lr, ln = ray[leaf], node[leaf]
                cnt = self.count[ln]
                pr = np.repeat(lr, cnt)
                first = np.repeat(self.start[ln] - (np.cumsum(cnt) - cnt), cnt)
                pp = self.order[first + np.arange(len(pr))]
                t = test(pr, pp, best_t[pr])
                hit = t < best_t[pr]
                if hit.any():
                    pr, pp, t = pr[hit], pp[hit], t[hit]
                    if any_hit:
                        done[pr] = True
                        best_t[pr] = t
                        best_p[pr] = pp
                    else:
                        np.minimum.at(best_t, pr, t)
                        win = t == best_t[pr]
                        best_p[pr[win]] = pp[win]
                inner = ~leaf
                ray, node = ray[inner], node[inner]
            ray = np.concatenate([ray, ray])
            node = np.concatenate([self.left[node], self.right[node]])
        return best_t, best_p


# --------------------------------------------------------------------------------------
# Primitive sets


class PrimitiveSet:
    """Primitives of one kind. Subclasses give the intersection kernels.

    As area lights, sample_light(k, p, r1, r2) gives AreaLight.sample's geometry:
    (direction, pdf, valid, t, point, geometric normal); by default the direction
    of sample_direction traced from p to the shape itself, as the scalar code.

    objects  the scalar objects (for fallbacks and tests); index = local index
    """

    objects: list[Hittable]
    bvh: BVH | None = None
    # sample_light accepts one int k for all rows (no per-row gathers of the shape)
    one_index_lights = False
    parts: list | None = None  # see cluster_parts

    def __len__(self) -> int:
        return len(self.objects)

    # ray parameter of (ray, primitive) pairs; arrays broadcast; inf where missed
    def pair_t(self, o, d, k, t_min, t_max) -> np.ndarray:
        raise NotImplementedError

    def all_t(
        self, o: np.ndarray, d: np.ndarray, t_min: float, t_max: np.ndarray | None = None
    ) -> np.ndarray:
        """(N, K) ray parameters of every ray against every primitive with t > t_min
        (inf: miss). The caller compares the smallest with each ray's t_max; a set may
        use t_max (N,), when given, to skip pairs that cannot hit before it."""
        k = np.arange(len(self))[None, :]
        return self.pair_t(o[:, None, :], d[:, None, :], k, t_min, INF)

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        raise NotImplementedError

    def build_bvh(self) -> None:
        if len(self) > BVH_THRESHOLD:
            self.bvh = BVH(*self.bounds())

    def closest(
        self,
        o: np.ndarray,
        d: np.ndarray,
        t_min: float,
        t_max: np.ndarray,
        any_hit: bool = False,
        skip: np.ndarray | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """(t, local index) of each ray's closest hit before t_max (t_max, -1 if none).
        any_hit: any hit will do (occlusion). skip: per ray, a primitive to ignore (-1:
        none)."""
        if self.bvh is not None:

            def test(r, p, tm):
                t = self.pair_t(o[r], d[r], p, t_min, tm)
                if skip is not None:
                    t[p == skip[r]] = INF
                return t

            return self.bvh.traverse(o, d, t_min, t_max, test, any_hit)
        if self.parts is not None:
            return self._closest_by_parts(o, d, t_min, t_max, any_hit, skip)
        t_best = np.array(t_max, dtype=np.float64, copy=True)
        idx = np.full(len(o), -1, dtype=np.int64)
        chunk = max(RAY_CHUNK, PAIR_CHUNK // len(self))
        row_start = np.arange(0, min(chunk, len(o)) * len(self), len(self))  # in t.ravel()
        for s in range(0, len(o), chunk):
            e = min(s + chunk, len(o))
            t = self.all_t(o[s:e], d[s:e], t_min, t_best[s:e] if any_hit else None)
            if skip is not None:
                r = np.flatnonzero(skip[s:e] >= 0)
                t[r, skip[s:e][r]] = INF
            j = np.argmin(t, axis=1)
            tj = t.ravel().take(row_start[: e - s] + j)  # t[i, j[i]]
            hit = tj < t_best[s:e]
            np.copyto(t_best[s:e], tj, where=hit)
            np.copyto(idx[s:e], j, where=hit)
        return t_best, idx

    def cluster(self) -> None:
        """Without a BVH: split the set into parts (cluster_parts), when that culls any."""
        if self.bvh is not None or len(self) < 2 * CLUSTER_SIZE:
            return
        lo, hi = self.bounds()
        groups = cluster_parts(self.corners(), lo, hi)
        if len(groups) < 2:
            return
        # One part per group: (box lo, box hi, the group as a set of its own, members);
        # the first part, the primitives in no cluster, has no box (every ray tests it).
        self.parts = []
        self.part_of = np.empty(len(self), dtype=np.int64)  # primitive -> its part
        self.part_pos = np.empty(len(self), dtype=np.int64)  # primitive -> index in part
        for g, members in enumerate(groups):
            if g == 0 and members.size == 0:
                continue
            sub = type(self)([self.objects[i] for i in members], cluster=False)
            box = (None, None) if g == 0 else _padded_box(lo[members], hi[members])
            self.part_of[members] = len(self.parts)
            self.part_pos[members] = np.arange(members.size)
            self.parts.append((*box, sub, members))

    def _closest_by_parts(self, o, d, t_min, t_max, any_hit, skip):
        """closest() over self.parts: each clustered part only for the rays that enter
        its box before the closest hit found so far (so the unclustered part goes first)."""
        t_best = np.array(t_max, dtype=np.float64, copy=True)
        idx = np.full(len(o), -1, dtype=np.int64)
        oc = np.ascontiguousarray(o.T)
        with np.errstate(divide="ignore"):
            inv = 1.0 / np.ascontiguousarray(d.T)
        for p, (lo, hi, part, members) in enumerate(self.parts):
            if lo is None:
                rays = None
                ro, rd, rt = o, d, t_best
            else:
                enter = _enters_box(oc, inv, lo, hi, t_min, t_best)
                if any_hit:
                    enter &= idx < 0
                rays = np.flatnonzero(enter)
                if rays.size == 0:
                    continue
                ro, rd, rt = o.take(rays, axis=0), d.take(rays, axis=0), t_best.take(rays)
            local_skip = None
            if skip is not None:
                sk = skip if rays is None else skip.take(rays)
                k = np.maximum(sk, 0)
                mine = (sk >= 0) & (self.part_of.take(k) == p)
                local_skip = np.where(mine, self.part_pos.take(k), -1)
            t, k = part.closest(ro, rd, t_min, rt, any_hit, local_skip)
            hit = np.flatnonzero(k >= 0)
            w = hit if rays is None else rays.take(hit)
            t_best[w] = t.take(hit)
            idx[w] = members.take(k.take(hit))
        return t_best, idx

    def corners(self) -> np.ndarray:
        """(K, C, 3) corners of the primitives (for clustering)."""
        raise NotImplementedError

    def sample_light(self, k, p, r1, r2):
        direction, pdf, valid = self.sample_direction(k, p, r1, r2)
        # Trace from p itself (not offset) to the shape, as AreaLight.sample.
        t = self.pair_t(p, direction, k, 0.0, INF)
        valid &= t < INF
        point, geo = self.geometric(k, p, direction, np.where(valid, t, 0.0))
        return direction, pdf, valid, t, point, geo

    # --- hit records ---------------------------------------------------------
    def geometric(self, k, o, d, t) -> tuple[np.ndarray, np.ndarray]:
        """(point, geometric unit normal) of hits on primitives k along rays at t."""
        raise NotImplementedError

    def uv(self, k, point) -> tuple[np.ndarray, np.ndarray]:
        raise NotImplementedError

    def tangent(self, k, point) -> tuple[np.ndarray, np.ndarray]:
        """(tangent (N, 3), valid (N,) bool): the scalar surface_tangent; invalid
        where it returns None (then HitInfo falls back to ONB(normal).u)."""
        raise NotImplementedError

    # --- as area lights ------------------------------------------------------
    def area(self, k) -> np.ndarray:
        raise NotImplementedError

    def sample_point(self, k, r1, r2) -> tuple[np.ndarray, np.ndarray]:
        raise NotImplementedError


def cluster_parts(corners: np.ndarray, lo: np.ndarray, hi: np.ndarray) -> list[np.ndarray]:
    """Groups of primitives worth culling together by one bounding box, as index arrays;
    the first holds the primitives in no such group (possibly none).

    A group is a connected set of primitives sharing corners (up to 1e-5 of the set's
    size: the six quads of a box), of at least CLUSTER_SIZE primitives, whose box has
    at most CLUSTER_AREA of the surface area of the whole set's box. In the Cornell
    box the two boxes are groups (a ray enters their boxes ~20% and ~15% of the time),
    the walls (whose box is the whole set's) and the light are not."""
    k = len(corners)
    extent = hi.max(axis=0) - lo.min(axis=0)
    tol = 1e-5 * float(extent.max())
    root = list(range(k))

    def find(i: int) -> int:
        while root[i] != i:
            i = root[i]
        return i

    for i in range(k):
        for j in range(i + 1, k):
            gap = np.abs(corners[i][:, None, :] - corners[j][None, :, :]).max(axis=2)
            if gap.min() <= tol:
                root[find(j)] = find(i)
    comps: dict[int, list[int]] = {}
    for i in range(k):
        comps.setdefault(find(i), []).append(i)
    whole = _box_area(lo.min(axis=0), hi.max(axis=0))
    free, groups = [], []
    for members in comps.values():
        m = np.array(members, dtype=np.int64)
        small = _box_area(lo[m].min(axis=0), hi[m].max(axis=0)) <= CLUSTER_AREA * whole
        if len(m) >= CLUSTER_SIZE and small:
            groups.append(m)
        else:
            free.extend(members)
    return [np.array(sorted(free), dtype=np.int64), *groups] if groups else []


def _box_area(lo: np.ndarray, hi: np.ndarray) -> float:
    e = np.maximum(hi - lo, 0.0)
    return float(2.0 * (e[0] * e[1] + e[1] * e[2] + e[2] * e[0]))


def _padded_box(lo: np.ndarray, hi: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The box around boxes lo, hi (K, 3), padded so rounding in the slab test cannot
    cull a ray that grazes a primitive on the box's boundary."""
    lo, hi = lo.min(axis=0), hi.max(axis=0)
    pad = 1e-7 * (float((hi - lo).max()) + float(np.abs(lo).max()) + float(np.abs(hi).max()))
    return lo - pad, hi + pad


def _enters_box(oc, inv, lo, hi, t_min: float, t_max: np.ndarray) -> np.ndarray:
    """(N,) bool: rays (origin columns oc (3, N), reciprocal direction columns inv)
    meet the box lo, hi at some t in (t_min, t_max) (slab test, one axis at a time).
    A zero direction component gives inv = +-inf; then (lo - o) * inv is nan only for
    an origin exactly on a slab plane, and nan comparisons count as entering."""
    near = far = None
    with np.errstate(invalid="ignore"):
        for c in range(3):
            a = (lo[c] - oc[c]) * inv[c]
            b = (hi[c] - oc[c]) * inv[c]
            n_c, f_c = np.minimum(a, b), np.maximum(a, b)
            near = n_c if near is None else np.fmax(near, n_c)
            far = f_c if far is None else np.fmin(far, f_c)
        return ~((near > far) | (far <= t_min) | (near >= t_max))


def _dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a.b over the last axis, summed in the scalar order x, y, z."""
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1] + a[..., 2] * b[..., 2]


def area_direction(
    p: np.ndarray, point: np.ndarray, normal: np.ndarray, area: np.ndarray
) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Hittable.sample_direction after sample_point: (direction, pdf, valid) for the
    direction from p to a point sampled by area, pdf = dist^2 / (|cos_light| area)."""
    dv = point - p
    dist2 = _dot(dv, dv)
    valid = dist2 != 0.0
    with np.errstate(divide="ignore", invalid="ignore"):
        k = 1.0 / np.sqrt(dist2)
        direction = scale(dv, k)
        cos_light = np.abs(_dot(direction, normal))
        valid &= cos_light >= 1e-12
        pdf = dist2 / (cos_light * area)
    return direction, np.where(valid, pdf, 0.0), valid


def area_direction_pdf(p: np.ndarray, q: np.ndarray, n: np.ndarray, area: np.ndarray) -> np.ndarray:
    """Hittable.direction_pdf: solid-angle density at p of area sampling picking q
    (normal n, either side)."""
    dv = q - p
    dist2 = _dot(dv, dv)
    # Grazing or coincident points divide by ~0 here; np.where below discards them.
    with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
        cos_light = np.abs(_dot(dv, n)) / np.sqrt(dist2)
        pdf = dist2 / (cos_light * area)
    return np.where((dist2 == 0.0) | ~(cos_light >= 1e-12), 0.0, pdf)


def _sphere_roots(h, c_term, a, r, f2, t_min, t_max):
    """Sphere.hit_t's root step, op for op (see rtpy/sphere.py): the nearer root of
    a t^2 - 2 h t + c_term = 0 inside (t_min, t_max), else INF; and q, which is 0
    where the roots are undefined. f2 is |f|^2, f the offset from the centre to the
    line's closest point, so disc = a (r - f)(r + f) needs no cancelling difference."""
    with np.errstate(invalid="ignore", divide="ignore"):
        f = np.sqrt(f2)
        disc = a * (r - f) * (r + f)
        q = h + np.copysign(np.sqrt(disc), h)
        t0 = c_term / q
        t1 = q / a
    lo = np.minimum(t0, t1)
    hi = np.maximum(t0, t1)
    t = np.where(t_min < lo, lo, hi)  # the nearer root past t_min (hi >= lo)
    return np.where((t_min < t) & (t < t_max), t, INF), q


def _cone_omc(d2, r2):
    """1 - cos_max of the cone that a sphere of squared radius r2 subtends at squared
    distance d2 from its centre (Sphere._cone), written without cancellation."""
    sin2 = r2 / d2
    return sin2 / (1.0 + np.sqrt(1.0 - sin2))


def _cone_direction(axis, omc, r1, r2):
    """Sphere.sample_direction inside the cone: ((x, y, z) world direction, cos_t,
    sin_t^2) at angle cos_t = 1 - r1 omc from the unit axis (from the shading point
    toward the centre), azimuth 2 pi r2 in the frame ONB(axis)."""
    cos_t = 1.0 - r1 * omc
    sin2_t = np.maximum(0.0, 1.0 - cos_t * cos_t)
    sin_t = np.sqrt(sin2_t)
    cos_phi, sin_phi = cos_sin_2pi(r2)
    return local_to_world(axis, sin_t * cos_phi, sin_t * sin_phi, cos_t), cos_t, sin2_t


class SphereSet(PrimitiveSet):
    """Spheres: center (K, 3), radius (K,). Geometric normal outward."""

    one_index_lights = True

    def __init__(self, spheres: Sequence[Sphere]) -> None:
        self.objects = list(spheres)
        self.center = np.array([_v(s.center) for s in spheres], dtype=np.float64).reshape(-1, 3)
        self.radius = np.array([float(s.radius) for s in spheres], dtype=np.float64)
        self.r2 = self.radius * self.radius
        self.center_columns = [self.center[:, c, None].copy() for c in range(3)]  # (K, 1)
        self.build_bvh()

    def bounds(self):
        r = self.radius[:, None]
        return self.center - r, self.center + r

    def pair_t(self, o, d, k, t_min, t_max):
        # Sphere.hit_t, operation for operation (see rtpy/sphere.py for the maths).
        c, r, r2 = at(self.center, k), at(self.radius, k), at(self.r2, k)
        dx, dy, dz = d[..., 0], d[..., 1], d[..., 2]
        ocx = c[..., 0] - o[..., 0]
        ocy = c[..., 1] - o[..., 1]
        ocz = c[..., 2] - o[..., 2]
        h = dx * ocx + dy * ocy + dz * ocz
        c_term = ocx * ocx + ocy * ocy + ocz * ocz - r2
        a = dx * dx + dy * dy + dz * dz
        kk = h / a
        fx = ocx - kk * dx
        fy = ocy - kk * dy
        fz = ocz - kk * dz
        f2 = fx * fx + fy * fy + fz * fz
        miss = ((h < 0.0) & (c_term > 0.0)) | (f2 > r2)
        t, q = _sphere_roots(h, c_term, a, r, f2, t_min, t_max)
        miss |= q == 0.0
        return np.where(miss, INF, t)

    def closest(self, o, d, t_min, t_max, any_hit=False, skip=None):
        """As PrimitiveSet.closest. Without a BVH, rays in chunks of SPHERE_CHUNK: a
        cheaper test than pair_t's (below) rejects, for every sphere and ray at once in
        (K, chunk) arrays (sphere by row, so numpy's inner loop runs over the rays),
        the pairs that surely miss; then sphere by sphere, pair_t's arithmetic, op for
        op, runs only for the rest, against the closest t found so far: t is
        bit-identical and ties keep the lower index (as argmin).

        The cheap test: pair_t misses where the sphere is behind an origin outside it
        (h < 0 and |oc|^2 > r^2), or where the line passes farther than r from the
        centre (f2 > r^2, f2 computed without cancellation). Here f2 is replaced by
        |oc|^2 - h^2 / a, which cancels but errs by only ~1e-15 |oc|^2, so rays are
        kept when it is at most r^2 + 1e-9 |oc|^2: a superset of pair_t's hits; the
        kept rays then get pair_t's exact test."""
        if self.bvh is not None:
            return super().closest(o, d, t_min, t_max, any_hit, skip)
        n = len(o)
        t_best = np.array(t_max, dtype=np.float64, copy=True)
        idx = np.full(n, -1, dtype=np.int64)
        for s in range(0, n, SPHERE_CHUNK):
            e = min(s + SPHERE_CHUNK, n)
            self._closest_chunk(
                o[s:e],
                d[s:e],
                t_min,
                t_best[s:e],
                idx[s:e],
                any_hit,
                None if skip is None else skip[s:e],
            )
        return t_best, idx

    def _closest_chunk(self, o, d, t_min, t_best, idx, any_hit, skip) -> None:
        """closest for one chunk of rays, updating t_best and idx (views into
        closest's results) in place. The chunk's components are copied to columns of
        their own (slices of columns of the whole batch would lie a power of two
        apart in memory and evict each other from the cache)."""
        n = len(o)
        ox, oy, oz = np.ascontiguousarray(o.T)
        dx, dy, dz = np.ascontiguousarray(d.T)
        a_all = dx * dx + dy * dy + dz * dz
        inv_a = 1.0 / a_all
        # The cheap test for all spheres at once: (K, n) arrays, sphere by row.
        cx, cy, cz = self.center_columns
        r2_col = self.r2[:, None]
        ocx_all, ocy_all, ocz_all = cx - ox, cy - oy, cz - oz
        h_all = dx * ocx_all
        h_all += dy * ocy_all
        h_all += dz * ocz_all
        oc2_all = ocx_all * ocx_all
        oc2_all += ocy_all * ocy_all
        oc2_all += ocz_all * ocz_all
        cand_all = oc2_all * (1.0 - 1e-9) - r2_col <= h_all * h_all * inv_a
        cand_all &= (h_all >= 0.0) | (oc2_all <= r2_col)
        for k in range(len(self)):
            r, r2 = self.radius[k], self.r2[k]
            h, oc2, cand = h_all[k], oc2_all[k], cand_all[k]
            ocx, ocy, ocz = ocx_all[k], ocy_all[k], ocz_all[k]
            if any_hit:
                cand &= idx < 0
            if skip is not None:
                cand &= skip != k
            if not cand.any():
                continue
            j = np.flatnonzero(cand)
            a, tm, jx, jy, jz = a_all, t_best, dx, dy, dz
            if j.size < n:
                h, oc2, ocx, ocy, ocz = h[j], oc2[j], ocx[j], ocy[j], ocz[j]
                a, tm, jx, jy, jz = a_all[j], t_best[j], dx[j], dy[j], dz[j]
            c_term = oc2 - r2
            kk = h / a
            fx = ocx - kk * jx
            fy = ocy - kk * jy
            fz = ocz - kk * jz
            f2 = fx * fx + fy * fy + fz * fz
            t, q = _sphere_roots(h, c_term, a, r, f2, t_min, tm)
            hit = (t < tm) & (q != 0.0) & (f2 <= r2)
            w = j[hit] if j.size < n else np.flatnonzero(hit)
            t_best[w] = t[hit]
            idx[w] = k

    def geometric(self, k, o, d, t):
        c, r = at(self.center, k), at(self.radius, k)
        p = axpy(t, d, o)
        nv = p - c
        inv = 1.0 / np.sqrt(_dot(nv, nv))
        n = scale(nv, inv)
        # Back onto the surface: removes the rounding of o + t d (as Sphere.hit_info).
        p = axpy(r, n, c)
        return p, n

    def uv(self, k, point):
        c, r = self.center[k], self.radius[k]
        x = (point[:, 0] - c[:, 0]) / r
        y = (point[:, 1] - c[:, 1]) / r
        z = (point[:, 2] - c[:, 2]) / r
        theta = np.arccos(np.clip(-y, -1.0, 1.0))
        phi = np.arctan2(-z, x) + math.pi
        return phi / (2.0 * math.pi), theta / math.pi

    def tangent(self, k, point):
        c = self.center[k]
        x = point[:, 0] - c[:, 0]
        z = point[:, 2] - c[:, 2]
        length = np.hypot(x, z)
        valid = ~(length < 1e-12 * self.radius[k])
        with np.errstate(divide="ignore", invalid="ignore"):
            tan = np.stack([z / length, np.zeros_like(x), -x / length], axis=1)
        return tan, valid

    def area(self, k):
        r = self.radius[k]
        return 4.0 * math.pi * r * r

    def sample_point(self, k, r1, r2):
        # sampling.uniform_sphere, then center + n * radius.
        z = 1.0 - 2.0 * r1
        s = np.sqrt(np.maximum(0.0, 1.0 - z * z))
        cos_phi, sin_phi = cos_sin_2pi(r2)
        n = np.stack([s * cos_phi, s * sin_phi, z], axis=1)
        return self.center[k] + n * self.radius[k][:, None], n

    def cone(self, k, p) -> tuple[np.ndarray, np.ndarray]:
        """Sphere._cone: (outside (N,) bool, 1 - cos_max) of the cone the sphere
        subtends at p; only meaningful where outside."""
        dv = at(self.center, k) - p
        d2 = _dot(dv, dv)
        r2 = at(self.r2, k)
        outside = ~(d2 <= r2 * 1.0000001)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # inside: unused
            return outside, _cone_omc(d2, r2)

    def sample_direction(self, k, p, r1, r2):
        """Sphere.sample_direction: by solid angle inside the cone seen from outside,
        by area from inside. Returns (direction, pdf, valid)."""
        outside, omc = self.cone(k, p)
        direction = np.empty_like(p)
        pdf = np.zeros(len(p))
        valid = np.zeros(len(p), dtype=bool)
        o = np.flatnonzero(outside)
        if o.size:
            every = o.size == len(p)  # all outside (the usual case): no gathers
            om = omc if every else omc.take(o)
            ko = k if every or isinstance(k, int) else k.take(o)
            po = p if every else p.take(o, axis=0)
            axis = at(self.center, ko) - po
            axis = scale(axis, 1.0 / np.sqrt(_dot(axis, axis)))
            dirs, _, _ = _cone_direction(
                (axis[:, 0], axis[:, 1], axis[:, 2]),
                om,
                r1 if every else r1.take(o),
                r2 if every else r2.take(o),
            )
            if every:
                direction = np.stack(dirs, axis=1)
                pdf = 1.0 / (2.0 * math.pi * om)
                valid[:] = True
                return direction, pdf, valid
            put_rows(direction, o, np.stack(dirs, axis=1))
            pdf[o] = 1.0 / (2.0 * math.pi * om)
            valid[o] = True
        i = np.flatnonzero(~outside)
        if i.size:
            if isinstance(k, int):
                k = np.full(len(p), k)
            q, n = self.sample_point(k[i], r1[i], r2[i])
            direction[i], pdf[i], valid[i] = area_direction(p[i], q, n, self.area(k[i]))
        return direction, pdf, valid

    def sample_light(self, k, p, r1, r2):
        """PrimitiveSet.sample_light fused for one sphere (int k) that every point p
        sees from outside (a sphere lamp): the offset from p to the centre, computed
        once, serves the cone, its axis and the distance to the sphere. The direction
        and pdf are op for op those of cone() and sample_direction(). The distance is
        not traced (pair_t) but follows from the sampled angle theta to the axis: the
        nearer root of t^2 - 2 t D cos(theta) + D^2 - r^2 = 0 (D = |centre - p|),
        written without cancellation as (D^2 - r^2) / (D cos(theta) + sqrt(r^2 -
        D^2 sin^2(theta))); it agrees with the trace to rounding (tested), except that a
        direction on the cone's very edge, which the trace may miss by rounding, still
        meets the sphere. Points inside the sphere take the general path."""
        if not isinstance(k, int):
            return super().sample_light(k, p, r1, r2)
        (cx, cy, cz), r, rr = self.center[k], self.radius[k], self.r2[k]
        px, py, pz = p[:, 0], p[:, 1], p[:, 2]
        ocx, ocy, ocz = cx - px, cy - py, cz - pz
        d2 = ocx * ocx + ocy * ocy + ocz * ocz
        if not (d2 > rr * 1.0000001).all():  # some point inside: the general path
            return super().sample_light(k, p, r1, r2)
        # The cone and a direction in it, as cone() and sample_direction().
        omc = _cone_omc(d2, rr)
        dist = np.sqrt(d2)
        inv = 1.0 / dist
        (dx, dy, dz), cos_t, sin2_t = _cone_direction(
            (ocx * inv, ocy * inv, ocz * inv), omc, r1, r2
        )
        pdf = 1.0 / (2.0 * math.pi * omc)
        # The distance to the sphere along the sampled direction (see above); inside
        # the cone, r^2 - D^2 sin^2 >= 0 but for rounding.
        t = (d2 - rr) / (dist * cos_t + np.sqrt(np.maximum(0.0, rr - d2 * sin2_t)))
        valid = np.ones(len(t), dtype=bool)
        # The point and its normal, as geometric().
        qx, qy, qz = px + t * dx, py + t * dy, pz + t * dz
        nx, ny, nz = qx - cx, qy - cy, qz - cz
        inv_n = 1.0 / np.sqrt(nx * nx + ny * ny + nz * nz)
        nx, ny, nz = nx * inv_n, ny * inv_n, nz * inv_n
        point = np.stack([cx + r * nx, cy + r * ny, cz + r * nz], axis=1)
        normal = np.stack([nx, ny, nz], axis=1)
        direction = np.stack([dx, dy, dz], axis=1)
        return direction, pdf, valid, t, point, normal

    def direction_pdf(self, k, p, q, n):
        outside, omc = self.cone(k, p)
        with np.errstate(divide="ignore"):
            cone_pdf = 1.0 / (2.0 * math.pi * omc)
        if outside.all():
            return cone_pdf
        return np.where(outside, cone_pdf, area_direction_pdf(p, q, n, self.area(k)))


class PlanarSet(PrimitiveSet):
    """Quads and triangles: a plane with unit normal n and two edge vectors. The
    all-pairs test is written as (N, 3) x (3, K) matrix products."""

    one_index_lights = True

    normal: np.ndarray
    origin: np.ndarray  # q or a
    tan: np.ndarray  # unit tangent (along u)
    _area: np.ndarray

    def tangent(self, k, point):
        return self.tan[k], np.ones(len(k), dtype=bool)

    def area(self, k):
        return at(self._area, k)

    def geometric(self, k, o, d, t):
        return axpy(t, d, o), self.normal.take(k, axis=0)

    def sample_direction(self, k, p, r1, r2):
        """Hittable.sample_direction: a point uniform by area, converted to solid angle.
        Returns (direction, pdf, valid)."""
        q, n = self.sample_point(k, r1, r2)
        return area_direction(p, q, n, self.area(k))

    def sample_light(self, k, p, r1, r2):
        """AreaLight.sample's geometry: (direction, pdf, valid, t, point, geometric
        normal). The sampled point is where the ray from p along the direction meets
        the plane, so it is not traced again (the scalar code traces it and gets the
        same point up to rounding)."""
        q, n = self.sample_point(k, r1, r2)
        direction, pdf, valid = area_direction(p, q, n, self.area(k))
        dv = q - p
        return direction, pdf, valid, np.sqrt(_dot(dv, dv)), q, n

    def direction_pdf(self, k, p, q, n):
        return area_direction_pdf(p, q, n, self.area(k))


class QuadSet(PlanarSet):
    """Quads q + a u + b v, a, b in [0, 1]; geometric normal normalize(u x v).

    With w = n / (n . n) for n = u x v, the scalar coordinates of a point p are
    a = w . ((p - q) x v) = (p - q) . (v x w) and b = w . (u x (p - q)) = (p - q) . (w x u),
    so for p = o + t d: a = o . A + t (d . A) - q . A with A = v x w (B = w x u likewise).
    """

    def __init__(self, quads: Sequence[Quad], cluster: bool = True) -> None:
        self.objects = list(quads)
        f = np.float64
        self.q = np.array([_v(s.q) for s in quads], dtype=f).reshape(-1, 3)
        self.u = np.array([_v(s.u) for s in quads], dtype=f).reshape(-1, 3)
        self.v = np.array([_v(s.v) for s in quads], dtype=f).reshape(-1, 3)
        self.w = np.array([_v(s.w) for s in quads], dtype=f).reshape(-1, 3)
        self.normal = np.array([_v(s.normal) for s in quads], dtype=f).reshape(-1, 3)
        self.plane_d = np.array([float(s.d) for s in quads], dtype=f)
        self.tan = np.array([_v(s._tangent) for s in quads], dtype=f).reshape(-1, 3)
        self._area = np.array([float(s.area()) for s in quads], dtype=f)
        self.origin = self.q
        self.A = np.cross(self.v, self.w)
        self.B = np.cross(self.w, self.u)
        self.qA = _dot(self.q, self.A)
        self.qB = _dot(self.q, self.B)
        # Products for all_t: (4, K) for homogeneous origins, (3, K) for directions.
        self.Mo_n = np.vstack([-self.normal.T, self.plane_d])
        self.Mo_a = np.vstack([2.0 * self.A.T, -2.0 * self.qA - 1.0])
        self.Mo_b = np.vstack([2.0 * self.B.T, -2.0 * self.qB - 1.0])
        self.Md_n = self.normal.T.copy()
        self.Md_a = 2.0 * self.A.T
        self.Md_b = 2.0 * self.B.T
        self.build_bvh()
        if cluster:
            self.cluster()

    def corners(self):
        return np.stack([self.q, self.q + self.u, self.q + self.v, self.q + self.u + self.v], 1)

    def bounds(self):
        corners = self.corners()
        return corners.min(axis=1), corners.max(axis=1)

    def all_t(self, o, d, t_min, t_max=None):
        """As PrimitiveSet.all_t. With t_max (N,) (occlusion), the edges are tested
        only for the quads whose plane some ray crosses in (t_min, t_max): a shadow
        ray inside a room crosses none of the walls' planes."""
        # Homogeneous o: one product gives d - o.n and 2 (o.A - q.A) - 1 (and for B),
        # so a' = 2a - 1 and b' = 2b - 1 need one multiply-add each and the test
        # 0 <= a, b <= 1 becomes max(|a'|, |b'|) <= 1.
        oh = np.empty((len(o), 4))
        oh[:, :3] = o
        oh[:, 3] = 1.0
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (oh @ self.Mo_n) / (d @ self.Md_n)
            if t_max is None:
                return self._inside(oh, d, t, t_min, slice(None))
            crossed = (t > t_min) & (t < t_max[:, None])
            cols = np.flatnonzero(crossed.any(axis=0))
            if cols.size == len(self):
                return self._inside(oh, d, t, t_min, slice(None))
            out = np.full(t.shape, INF)
            if cols.size:
                out[:, cols] = self._inside(oh, d, t[:, cols], t_min, cols)
            return out

    def _inside(self, oh, d, t, t_min, cols):
        """t where the hits at t on the quads cols lie inside them (else inf)."""
        a = oh @ self.Mo_a[:, cols]
        a += t * (d @ self.Md_a[:, cols])
        b = oh @ self.Mo_b[:, cols]
        b += t * (d @ self.Md_b[:, cols])
        np.abs(a, out=a)
        np.abs(b, out=b)
        np.maximum(a, b, out=a)
        ok = a <= EDGE
        ok &= t > t_min
        return np.where(ok, t, INF)

    def pair_t(self, o, d, k, t_min, t_max):
        n = self.normal[k]
        A, B = self.A[k], self.B[k]
        with np.errstate(divide="ignore", invalid="ignore"):
            t = (self.plane_d[k] - _dot(n, o)) / _dot(n, d)
            a = _dot(o, A) - self.qA[k] + t * _dot(d, A)
            b = _dot(o, B) - self.qB[k] + t * _dot(d, B)
        ok = (t > t_min) & (t < t_max) & (a >= -EDGE_A) & (a <= 1.0 + EDGE_A)
        ok &= (b >= -EDGE_A) & (b <= 1.0 + EDGE_A)
        return np.where(ok, t, INF)

    def uv(self, k, point):
        # Quad._coords, then clamped to [0, 1].
        q, w, u, v = self.q[k], self.w[k], self.u[k], self.v[k]
        px, py, pz = point[:, 0] - q[:, 0], point[:, 1] - q[:, 1], point[:, 2] - q[:, 2]
        a = (
            w[:, 0] * (py * v[:, 2] - pz * v[:, 1])
            + w[:, 1] * (pz * v[:, 0] - px * v[:, 2])
            + w[:, 2] * (px * v[:, 1] - py * v[:, 0])
        )
        b = (
            w[:, 0] * (u[:, 1] * pz - u[:, 2] * py)
            + w[:, 1] * (u[:, 2] * px - u[:, 0] * pz)
            + w[:, 2] * (u[:, 0] * py - u[:, 1] * px)
        )
        return np.clip(a, 0.0, 1.0), np.clip(b, 0.0, 1.0)

    def sample_point(self, k, r1, r2):
        # q + r1 u + r2 v, column by column
        p = axpy(r1, at(self.u, k), at(self.q, k))
        v = at(self.v, k)
        for c in range(3):
            p[:, c] += r2 * v[..., c]
        return p, at(self.normal, k)


class TriangleSet(PlanarSet):
    """Triangles a, b, c; geometric normal normalize((b - a) x (c - a)).

    Moller-Trumbore in Plucker form: with e1 = b - a, e2 = c - a, m = o x d and
    N = e1 x e2, det = -(d . N), u det = e2 . m - d . (e2 x a),
    v det = -(e1 . m) - d . (a x e1), t det = o . N - a . N (all K-sided factors
    are precomputed; the ray-sided ones are (N, 3) x (3, K) products).
    """

    def __init__(self, triangles: Sequence[Triangle], cluster: bool = True) -> None:
        self.objects = list(triangles)
        f = np.float64
        self.a = np.array([_v(s.a) for s in triangles], dtype=f).reshape(-1, 3)
        self.e1 = np.array([_v(s.e1) for s in triangles], dtype=f).reshape(-1, 3)
        self.e2 = np.array([_v(s.e2) for s in triangles], dtype=f).reshape(-1, 3)
        self.normal = np.array([_v(s.normal) for s in triangles], dtype=f).reshape(-1, 3)
        self.tan = np.array([_v(s._tangent) for s in triangles], dtype=f).reshape(-1, 3)
        self._area = np.array([float(s.area()) for s in triangles], dtype=f)
        # Triangle's relative parallel test: det^2 <= parallel_det2 * |d|^2 is a miss.
        self.parallel_det2 = np.array([s._parallel_det2 for s in triangles], dtype=f)
        self.origin = self.a
        self.N = np.cross(self.e1, self.e2)
        self.e2xa = np.cross(self.e2, self.a)
        self.axe1 = np.cross(self.a, self.e1)
        self.aN = _dot(self.a, self.N)
        # o-side: [N]; d-side: [N, e2 x a, a x e1]; m-side: [e2, e1]
        self.Mo = self.N.T.copy()
        self.Md = np.concatenate([self.N, self.e2xa, self.axe1], axis=0).T.copy()
        self.Mm = np.concatenate([self.e2, self.e1], axis=0).T.copy()
        self.build_bvh()
        if cluster:
            self.cluster()

    def corners(self):
        return np.stack([self.a, self.a + self.e1, self.a + self.e2], 1)

    def bounds(self):
        corners = self.corners()
        return corners.min(axis=1), corners.max(axis=1)

    def _finish(self, det, parallel, u_num, v_num, t_num, t_min, t_max):
        with np.errstate(divide="ignore", invalid="ignore"):
            inv = 1.0 / det
            u = u_num * inv
            v = v_num * inv
            t = t_num * inv
        ok = (det * det > parallel) & (u >= 0.0) & (u <= 1.0) & (v >= 0.0) & (u + v <= 1.0)
        ok &= (t > t_min) & (t < t_max)
        return np.where(ok, t, INF)

    def all_t(self, o, d, t_min, t_max=None):
        k = len(self)
        m = np.cross(o, d)
        on = o @ self.Mo
        dd = d @ self.Md
        mm = m @ self.Mm
        det = -dd[:, :k]
        u_num = mm[:, :k] - dd[:, k : 2 * k]
        v_num = -mm[:, k:] - dd[:, 2 * k :]
        t_num = on - self.aN
        parallel = self.parallel_det2 * _dot(d, d)[:, None]
        return self._finish(det, parallel, u_num, v_num, t_num, t_min, INF)

    def pair_t(self, o, d, k, t_min, t_max):
        m = np.cross(o, d)
        nn = self.N[k]
        det = -_dot(d, nn)
        u_num = _dot(self.e2[k], m) - _dot(d, self.e2xa[k])
        v_num = -_dot(self.e1[k], m) - _dot(d, self.axe1[k])
        t_num = _dot(o, nn) - self.aN[k]
        parallel = self.parallel_det2[k] * _dot(d, d)
        return self._finish(det, parallel, u_num, v_num, t_num, t_min, t_max)

    def uv(self, k, point):
        # Triangle.surface_uv: barycentric coordinates from dot products.
        p = point - self.a[k]
        e1, e2 = self.e1[k], self.e2[k]
        d00, d01, d11 = _dot(e1, e1), _dot(e1, e2), _dot(e2, e2)
        d20, d21 = _dot(p, e1), _dot(p, e2)
        denom = d00 * d11 - d01 * d01
        u = (d11 * d20 - d01 * d21) / denom
        v = (d00 * d21 - d01 * d20) / denom
        return np.clip(u, 0.0, 1.0), np.clip(v, 0.0, 1.0)

    def sample_point(self, k, r1, r2):
        s = np.sqrt(r1)
        wb, wc = s * (1.0 - r2), s * r2
        p = self.a[k] + wb[:, None] * self.e1[k] + wc[:, None] * self.e2[k]
        return p, self.normal[k]


class ScalarSet(PrimitiveSet):
    """Shapes without a batched twin, intersected by their scalar methods per ray."""

    def __init__(self, objects: Sequence[Hittable]) -> None:
        self.objects = list(objects)

    def _rays(self, o, d):
        return [
            Ray(Vec3(*map(float, oi)), Vec3(*map(float, di))) for oi, di in zip(o, d, strict=True)
        ]

    def closest(self, o, d, t_min, t_max, any_hit=False, skip=None):
        t_best = np.array(t_max, dtype=np.float64, copy=True)
        idx = np.full(len(o), -1, dtype=np.int64)
        for i, ray in enumerate(self._rays(o, d)):
            for j, obj in enumerate(self.objects):
                if skip is not None and skip[i] == j:
                    continue
                t = obj.hit_t(ray, t_min, float(t_best[i]))
                if t is not None:
                    t_best[i], idx[i] = t, j
                    if any_hit:
                        break
        return t_best, idx

    def pair_t(self, o, d, k, t_min, t_max):
        o, d = np.broadcast_arrays(o, d)
        k, t_max = np.broadcast_to(k, o.shape[:-1]), np.broadcast_to(t_max, o.shape[:-1])
        out = np.full(o.shape[:-1], INF)
        for i in np.ndindex(out.shape):
            ray = Ray(Vec3(*map(float, o[i])), Vec3(*map(float, d[i])))
            t = self.objects[int(k[i])].hit_t(ray, t_min, float(t_max[i]))
            out[i] = INF if t is None else t
        return out

    def _infos(self, k, o, d, t) -> list[HitInfo]:
        return [
            self.objects[int(ki)].hit_info(ray, float(ti))
            for ki, ray, ti in zip(k, self._rays(o, d), t, strict=True)
        ]

    def geometric(self, k, o, d, t):
        infos = self._infos(k, o, d, t)
        p = np.array([_v(h.point) for h in infos]).reshape(-1, 3)
        n = np.array([_v(h.normal) for h in infos]).reshape(-1, 3)
        # Back to the geometric side: HitInfo's normal faces the ray.
        flip = np.array([not h.front_face for h in infos], dtype=bool)
        n[flip] *= -1.0
        return p, n

    def _hit(self, ki, point) -> HitInfo:
        return HitInfo(Vec3(*map(float, point)), Vec3(0.0, 0.0, 1.0), 0.0, True, None, None)

    def uv(self, k, point):
        pairs = zip(k, point, strict=True)
        uv = [self.objects[int(ki)].surface_uv(self._hit(ki, p)) for ki, p in pairs]
        uv = np.array(uv, dtype=np.float64).reshape(-1, 2)
        return uv[:, 0], uv[:, 1]

    def tangent(self, k, point):
        tan = np.zeros((len(k), 3))
        valid = np.zeros(len(k), dtype=bool)
        for i, (ki, p) in enumerate(zip(k, point, strict=True)):
            s = self.objects[int(ki)].surface_tangent(self._hit(ki, p))
            if s is not None:
                tan[i], valid[i] = _v(s), True
        return tan, valid

    def area(self, k):
        return np.array([self.objects[int(ki)].area() for ki in k], dtype=np.float64)

    def sample_direction(self, k, p, r1, r2):
        direction = np.zeros((len(k), 3))
        pdf = np.zeros(len(k))
        valid = np.zeros(len(k), dtype=bool)
        for i in range(len(k)):
            s = self.objects[int(k[i])].sample_direction(
                Vec3(*map(float, p[i])), float(r1[i]), float(r2[i])
            )
            if s is not None:
                direction[i], pdf[i], valid[i] = _v(s[0]), s[1], True
        return direction, pdf, valid

    def direction_pdf(self, k, p, q, n):
        out = np.zeros(len(k))
        for i in range(len(k)):
            hit = HitInfo(Vec3(*map(float, q[i])), Vec3(*map(float, n[i])), 0.0, True, None)
            out[i] = self.objects[int(k[i])].direction_pdf(Vec3(*map(float, p[i])), hit)
        return out


# --------------------------------------------------------------------------------------
# The whole scene


SPHERE, QUAD, TRIANGLE, OTHER = 0, 1, 2, 3


class Geometry:
    """All objects of a scene as primitive sets.

    Object i (index into `objects`) is primitive local[i] of set sets[kind[i]];
    `material_id[i]` is its material's index in `materials` (distinct materials
    in first-use order, the ids a MaterialTable gets).
    """

    def __init__(self, objects: Sequence[Hittable]) -> None:
        self.objects = list(objects)
        n = len(self.objects)
        self.kind = np.empty(n, dtype=np.int64)
        self.local = np.empty(n, dtype=np.int64)
        groups: list[list[int]] = [[], [], [], []]
        for i, obj in enumerate(self.objects):
            # Exact types: a subclass may override hit_t (tests do), so it goes scalar.
            kind = {Sphere: SPHERE, Quad: QUAD, Triangle: TRIANGLE}.get(type(obj), OTHER)
            self.kind[i] = kind
            self.local[i] = len(groups[kind])
            groups[kind].append(i)
        self.members = [np.array(g, dtype=np.int64) for g in groups]  # set -> object index
        makers = (SphereSet, QuadSet, TriangleSet, ScalarSet)
        self.sets: list[PrimitiveSet | None] = [
            makers[kd]([self.objects[i] for i in g]) if g else None for kd, g in enumerate(groups)
        ]
        self.materials: list = []
        ids: dict[int, int] = {}
        self.material_id = np.empty(n, dtype=np.int64)
        for i, obj in enumerate(self.objects):
            key = id(obj.material)
            if key not in ids:
                ids[key] = len(self.materials)
                self.materials.append(obj.material)
            self.material_id[i] = ids[key]

    def _order(self):
        # Brute-force sets first: their hits give the BVH traversals a t_max to prune with.
        return sorted(
            (kd for kd in range(4) if self.sets[kd] is not None),
            key=lambda kd: (self.sets[kd].bvh is not None, kd == OTHER),
        )

    def closest_hit(
        self, o: np.ndarray, d: np.ndarray, t_max: np.ndarray | None = None
    ) -> tuple[np.ndarray, np.ndarray]:
        """(object index (N,), -1 for a miss; t (N,)) of each ray's closest hit with
        0 < t < t_max (default inf), as Scene.find_intersection(ray, FORWARD)."""
        n = len(o)
        t_best = np.full(n, INF) if t_max is None else np.array(t_max, dtype=np.float64)
        obj = np.full(n, -1, dtype=np.int64)
        order = self._order()
        if len(order) == 1:  # one kind of primitive: its answer as it is
            t, k = self.sets[order[0]].closest(o, d, 0.0, t_best)
            return np.where(k >= 0, self.members[order[0]].take(k), -1), t
        for kd in order:
            t, k = self.sets[kd].closest(o, d, 0.0, t_best)
            hit = k >= 0
            t_best[hit] = t[hit]
            obj[hit] = self.members[kd][k[hit]]
        return obj, t_best

    def occluded(
        self,
        o: np.ndarray,
        d: np.ndarray,
        t_max: np.ndarray,
        skip: np.ndarray | None = None,
    ) -> np.ndarray:
        """(N,) bool: something (glass included) lies on the ray with 0 < t < t_max,
        as Scene.find_occlusion(ray, Interval(0, t_max)); skip: per ray, an object
        index to ignore (-1: none)."""
        blocked = np.zeros(len(o), dtype=bool)
        for kd in self._order():
            live = np.flatnonzero(~blocked)
            if live.size == 0:
                break
            local_skip = None
            if skip is not None:
                sk = skip[live]
                local_skip = np.where((sk >= 0) & (self.kind[sk] == kd), self.local[sk], -1)
                if not (local_skip >= 0).any():
                    local_skip = None
            if live.size == len(o):  # no gathers
                _, k = self.sets[kd].closest(o, d, 0.0, t_max, any_hit=True, skip=local_skip)
                blocked = k >= 0
                continue
            _, k = self.sets[kd].closest(
                rows(o, live), rows(d, live), 0.0, t_max[live], any_hit=True, skip=local_skip
            )
            blocked[live[k >= 0]] = True
        return blocked

    def _groups(self, obj: np.ndarray) -> tuple[np.ndarray, list[tuple[int, np.ndarray | slice]]]:
        """(local indices, [(kind, positions in obj)]) with a slice for a single kind."""
        kinds = self.kind[obj]
        local = self.local[obj]
        present = [kd for kd in range(4) if self.sets[kd] is not None]
        if len(present) == 1:
            return local, [(present[0], slice(None))]
        groups = [(kd, np.flatnonzero(kinds == kd)) for kd in present]
        return local, [(kd, i) for kd, i in groups if i.size]

    def hit_batch(
        self,
        obj: np.ndarray,
        o: np.ndarray,
        d: np.ndarray,
        t: np.ndarray,
        need_uv: bool = True,
        need_tangent: bool = True,
    ) -> HitBatch:
        """The HitBatch of rays (o, d) hitting objects obj at t (all hits, obj >= 0).
        Without need_uv / need_tangent those fields are zeros (nothing reads them)."""
        local, groups = self._groups(obj)
        if len(groups) == 1:
            kd, _ = groups[0]
            point, geo = self.sets[kd].geometric(local, o, d, t)
        else:
            n = len(obj)
            point, geo = np.empty((n, 3)), np.empty((n, 3))
            for kd, i in groups:
                point[i], geo[i] = self.sets[kd].geometric(local[i], o[i], d[i], t[i])
        return self.hits_at(obj, point, geo, d, t, need_uv, need_tangent, (local, groups))

    def hits_at(
        self,
        obj: np.ndarray,
        point: np.ndarray,
        geo: np.ndarray,
        d: np.ndarray,
        t: np.ndarray,
        need_uv: bool = True,
        need_tangent: bool = True,
        grouped=None,
    ) -> HitBatch:
        """The HitBatch of rays with directions d reaching `point` (geometric normal
        `geo`) on objects obj after distance t."""
        n = len(obj)
        local, groups = grouped if grouped is not None else self._groups(obj)
        front = _dot(geo, d) < 0.0
        normal = scale(geo, np.where(front, 1.0, -1.0))
        if need_uv:
            u, v = np.empty(n), np.empty(n)
            for kd, i in groups:
                u[i], v[i] = self.sets[kd].uv(local[i], point[i])
        else:
            u = v = unused(n)
        if need_tangent:
            tangent = np.empty((n, 3))
            valid = np.empty(n, dtype=bool)
            for kd, i in groups:
                tangent[i], valid[i] = self.sets[kd].tangent(local[i], point[i])
            if not valid.all():
                bad = ~valid
                tangent[bad] = onb_u(normal[bad])
        else:
            tangent = unused(n, 3)
        return HitBatch(point, normal, -d, t, front, u, v, tangent)

    def set_of(self, obj: np.ndarray):
        """[(set, local indices, positions in obj)] grouping objects by kind; the
        positions are slice(None) when all objects are of one kind."""
        kinds = self.kind[obj]
        if len(kinds) and (kinds == kinds[0]).all():
            return [(self.sets[kinds[0]], self.local[obj], slice(None))]
        out = []
        for kd in range(4):
            i = np.flatnonzero(kinds == kd)
            if i.size:
                out.append((self.sets[kd], self.local[obj[i]], i))
        return out
