"""Culling for primitive sets: a bounding volume hierarchy, and clusters of planar primitives.

BVH is the batched twin of rtpy/bvh.py: a binary tree of axis-aligned boxes (binned
surface area heuristic) stored as arrays, which all rays of a batch descend together,
level by level, so a set of hundreds of spheres costs only the boxes and primitives
each ray comes near.

Clusters serve a brute-force set of planar primitives (a few dozen quads, as the
Cornell box): connected groups of primitives (the six quads of a box) are culled by
their bounding box, so a ray tests their primitives only when it enters the box
before the closest hit found so far.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from .arrays import max3
from .ray import ray_columns

if TYPE_CHECKING:
    from .hittable import PrimitiveSet

BVH_LEAF_SIZE = 4
# Clusters hold at least CLUSTER_SIZE primitives, and their box has at most CLUSTER_AREA
# of the surface area of the whole set's box.
CLUSTER_SIZE = 3
CLUSTER_AREA = 0.5
# Rays per chunk of the clusters' slab test.
BOX_CHUNK = 8192


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
        heuristic), or None when keeping a leaf is cheaper. The boxes on either side
        of every plane come from running min/max over the bins' boxes; of equal costs
        the first in (axis, plane) order wins."""

        def area(a, b):
            e = np.maximum(b - a, 0.0)
            return 2.0 * (e[..., 0] * e[..., 1] + e[..., 1] * e[..., 2] + e[..., 2] * e[..., 0])

        c, box_lo, box_hi, n = centroid[idx], lo[idx], hi[idx], len(idx)
        leaf_cost = area(box_lo.min(0), box_hi.max(0)) * n
        cost = np.full((3, bins - 1), np.inf)
        binned = []
        for axis in range(3):
            cmin, cmax = c[:, axis].min(), c[:, axis].max()
            if not cmax > cmin:
                binned.append(None)
                continue
            b = np.minimum(((c[:, axis] - cmin) / (cmax - cmin) * bins).astype(int), bins - 1)
            binned.append(b)
            bin_lo, bin_hi = np.full((bins, 3), np.inf), np.full((bins, 3), -np.inf)
            np.minimum.at(bin_lo, b, box_lo)
            np.maximum.at(bin_hi, b, box_hi)
            n_left = np.cumsum(np.bincount(b, minlength=bins))[:-1]  # for planes 1 .. bins-1
            left = area(np.minimum.accumulate(bin_lo)[:-1], np.maximum.accumulate(bin_hi)[:-1])
            right_lo = np.minimum.accumulate(bin_lo[::-1])[::-1][1:]
            right_hi = np.maximum.accumulate(bin_hi[::-1])[::-1][1:]
            split = left * n_left + area(right_lo, right_hi) * (n - n_left)
            cost[axis] = np.where((n_left > 0) & (n_left < n), split, np.inf)
        axis, plane = np.unravel_index(np.argmin(cost), cost.shape)
        if cost[axis, plane] < leaf_cost:
            m = binned[axis] < plane + 1
            return idx[m], idx[~m]
        if len(idx) > 4 * BVH_LEAF_SIZE:
            # All centroids together (or no better split): halve by index.
            half = len(idx) // 2
            return idx[:half], idx[half:]
        return None

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
            ro, ri = o.take(ray, axis=0), inv.take(ray, axis=0)
            with np.errstate(invalid="ignore", over="ignore"):
                t0 = (self.lo.take(node, axis=0) - ro) * ri
                t1 = (self.hi.take(node, axis=0) - ro) * ri
            near = max3(np.minimum(t0, t1))
            lo = np.maximum(t0, t1)
            far = np.minimum(np.minimum(lo[:, 0], lo[:, 1]), lo[:, 2])
            keep = (near <= far) & (far > t_min) & (near < best_t.take(ray))
            if any_hit:
                keep &= ~done.take(ray)
            ray, node = ray.compress(keep), node.compress(keep)
            cnt = self.count.take(node)
            leaf = cnt > 0
            if leaf.any():
                lr, ln, cnt = ray.compress(leaf), node.compress(leaf), cnt.compress(leaf)
                pr = np.repeat(lr, cnt)
                first = np.repeat(self.start.take(ln) - (np.cumsum(cnt) - cnt), cnt)
                pp = self.order.take(first + np.arange(len(pr)))
                t = test(pr, pp, best_t.take(pr))
                hit = t < best_t.take(pr)
                if hit.any():
                    pr, pp, t = pr.compress(hit), pp.compress(hit), t.compress(hit)
                    if any_hit:
                        done[pr] = True
                        best_t[pr] = t
                        best_p[pr] = pp
                    else:
                        np.minimum.at(best_t, pr, t)
                        win = t == best_t.take(pr)
                        best_p[pr.compress(win)] = pp.compress(win)
                inner = ~leaf
                ray, node = ray.compress(inner), node.compress(inner)
            ray = np.concatenate([ray, ray])
            node = np.concatenate([self.left.take(node), self.right.take(node)])
        return best_t, best_p


class Clusters:
    """A brute-force set split into parts: the first without a box (the primitives in
    no cluster, tested by every ray), then one part per cluster, each its own set of
    the same kind with the box around its primitives.

    parts     [(box lo or None, box hi or None, the part as a set, its members)]
    part_of   (K,) the part of each primitive of the whole set
    part_pos  (K,) its index in that part
    """

    def __init__(self, prims: PrimitiveSet, groups: list[np.ndarray]) -> None:
        lo, hi = prims.bounding_boxes()
        self.parts: list[tuple] = []
        self.part_of = np.empty(len(prims), dtype=np.int64)
        self.part_pos = np.empty(len(prims), dtype=np.int64)
        for g, members in enumerate(groups):
            if g == 0 and members.size == 0:
                continue
            sub = type(prims)([prims.objects[i] for i in members], cluster=False)
            box = (None, None) if g == 0 else _padded_box(lo[members], hi[members])
            self.part_of[members] = len(self.parts)
            self.part_pos[members] = np.arange(members.size)
            self.parts.append((*box, sub, members))

    @classmethod
    def build(cls, prims: PrimitiveSet) -> Clusters | None:
        """The clusters of a planar set, or None when they would cull nothing."""
        if len(prims) < 2 * CLUSTER_SIZE:
            return None
        groups = cluster_parts(prims.corners(), *prims.bounding_boxes())
        return cls(prims, groups) if len(groups) >= 2 else None

    def closest_hit(self, o, d, t_min, t_max, any_hit, ignore):
        """PrimitiveSet.closest_hit over the parts: each clustered part only for the
        rays that enter its box before the closest hit found so far (so the part
        without a box goes first)."""
        t_best = np.array(t_max, dtype=np.float64, copy=True)
        idx = np.full(len(o), -1, dtype=np.int64)
        columns = ray_columns(o, d)
        with np.errstate(divide="ignore", over="ignore"):  # 0 or subnormal: +-inf
            inv = 1.0 / columns[1]
        for p, (lo, hi, part, members) in enumerate(self.parts):
            if lo is None:
                rays = None
                ro, rd, rt, cols = o, d, t_best, columns
            else:
                enter = _enters_box(columns[0], inv, lo, hi, t_min, t_best)
                if any_hit:
                    enter &= idx < 0
                rays = np.flatnonzero(enter)
                if rays.size == 0:
                    continue
                ro, rd, rt = o.take(rays, axis=0), d.take(rays, axis=0), t_best.take(rays)
                cols = None
            local_ignore = None
            if ignore is not None:
                ig = ignore if rays is None else ignore.take(rays)
                k = np.maximum(ig, 0)
                mine = (ig >= 0) & (self.part_of.take(k) == p)
                local_ignore = np.where(mine, self.part_pos.take(k), -1)
            t, k = part.closest_hit(ro, rd, t_min, rt, any_hit, local_ignore, cols)
            hit = np.flatnonzero(k >= 0)
            w = hit if rays is None else rays.take(hit)
            t_best[w] = t.take(hit)
            idx[w] = members.take(k.take(hit))
        return t_best, idx


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
    """(N,) bool: rays (origin columns oc (3+, N), reciprocal direction columns inv)
    meet the box lo, hi at some t in (t_min, t_max) (slab test, one axis at a time).
    A zero (or subnormal) direction component gives inv = +-inf; then (lo - o) * inv is
    nan only for an origin exactly on a slab plane, and nan comparisons count as
    entering. A huge finite inv may overflow the product to +-inf likewise. Rays go
    in chunks of BOX_CHUNK, so the temporaries stay in cache."""
    out = np.empty(len(t_max), dtype=bool)
    with np.errstate(invalid="ignore", over="ignore"):
        for s in range(0, len(t_max), BOX_CHUNK):
            e = s + BOX_CHUNK
            near = far = None
            for c in range(3):
                a = np.subtract(lo[c], oc[c, s:e])
                a *= inv[c, s:e]
                f_c = np.subtract(hi[c], oc[c, s:e])
                f_c *= inv[c, s:e]
                n_c = np.minimum(a, f_c)
                np.maximum(a, f_c, out=f_c)
                if near is None:
                    near, far = n_c, f_c
                else:
                    np.fmax(near, n_c, out=near)
                    np.fmin(far, f_c, out=far)
            miss = near > far
            miss |= far <= t_min
            miss |= near >= t_max[s:e]
            np.logical_not(miss, out=out[s:e])
    return out
