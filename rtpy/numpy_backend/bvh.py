"""Culling for primitive sets: a bounding volume hierarchy, and clusters of planar primitives.

BVH is the batched twin of rtpy/bvh.py's search: the same flat tree (rtpy.bvh.Tree,
built by rtpy/_bvh_build.py), which all rays of a batch descend together, level by
level, so a set of hundreds of spheres or a mesh of a million triangles costs only
the boxes and primitives each ray comes near.

Clusters serve a brute-force set of planar primitives (a few dozen quads, as the
Cornell box): connected groups of primitives (the six quads of a box) are culled by
their bounding box, so a ray tests their primitives only when it enters the box
before the closest hit found so far.
"""

from __future__ import annotations

from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from .. import _bvh_build as bvh_build
from .arrays import max3
from .ray import ray_columns

if TYPE_CHECKING:
    from .hittable import PrimitiveSet

# Clusters hold at least CLUSTER_SIZE primitives, and their box has at most CLUSTER_AREA
# of the surface area of the whole set's box.
CLUSTER_SIZE = 3
CLUSTER_AREA = 0.5
# Rays per chunk of the clusters' slab test.
BOX_CHUNK = 8192


class BVH:
    """The search of an rtpy.bvh.Tree for many rays at once.

    Built from K axis-aligned boxes (rtpy._bvh_build), or given a tree built already
    (a Mesh's, which travels with the scene to every worker).
    """

    def __init__(self, lo: np.ndarray | None = None, hi: np.ndarray | None = None, tree=None):
        if tree is None:
            tree = bvh_build.build_tree(lo, hi)
        self.tree = tree
        self.lo, self.hi, self.child, self.count = tree.lo, tree.hi, tree.child, tree.count
        self.order = tree.order

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
        hit before t_max; of primitives hit at the same t, the one of the smallest
        index, as the scalar BVH. All rays descend the tree together, one level per
        iteration; leaves found at a level are tested at once and shrink the rays'
        t_max, which prunes the boxes of later levels.
        """
        n = len(o)
        best_t = np.array(t_max, dtype=np.float64, copy=True)
        none = np.iinfo(np.int64).max
        best_p = np.full(n, none, dtype=np.int64)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            safe = np.where(np.abs(d) < 1e-300, np.copysign(1e-300, d), d)
            inv = 1.0 / safe
        lo, hi, child, count, order = self.lo, self.hi, self.child, self.count, self.order
        ray = np.arange(n)
        node = np.zeros(n, dtype=np.int64)
        done = np.zeros(n, dtype=bool)
        while ray.size:
            ro, ri = o.take(ray, axis=0), inv.take(ray, axis=0)
            with np.errstate(invalid="ignore", over="ignore"):
                t0 = (lo.take(node, axis=0) - ro) * ri
                t1 = (hi.take(node, axis=0) - ro) * ri
            near = max3(np.minimum(t0, t1))
            np.maximum(t0, t1, out=t1)
            far = np.minimum(np.minimum(t1[:, 0], t1[:, 1]), t1[:, 2])
            # near <= best_t: a primitive hit at best_t itself may still win the tie
            keep = (near <= far) & (far > t_min) & (near <= best_t.take(ray))
            if any_hit:
                keep &= ~done.take(ray)
            ray, node = ray.compress(keep), node.compress(keep)
            cnt = count.take(node)
            leaf = cnt > 0
            if leaf.any():
                lr, ln, cnt = ray.compress(leaf), node.compress(leaf), cnt.compress(leaf)
                pr = np.repeat(lr, cnt)
                first = np.repeat(child.take(ln) - (np.cumsum(cnt) - cnt), cnt)
                pp = order.take(first + np.arange(len(pr)))
                bound = best_t.take(pr)
                if not any_hit:  # past a hit, the next float up: a tie at best_t comes back
                    bound = np.where(best_p.take(pr) == none, bound, np.nextafter(bound, np.inf))
                t = test(pr, pp, bound)
                hit = t < bound
                if hit.any():
                    pr, pp, t = pr.compress(hit), pp.compress(hit), t.compress(hit)
                    if any_hit:
                        done[pr] = True
                        best_t[pr] = t
                        best_p[pr] = pp
                    else:
                        before = best_t.take(pr)
                        np.minimum.at(best_t, pr, t)
                        after = best_t.take(pr)
                        best_p[pr.compress(after < before)] = none  # a nearer hit: a new tie
                        win = t == after
                        np.minimum.at(best_p, pr.compress(win), pp.compress(win))
                inner = ~leaf
                ray, node = ray.compress(inner), node.compress(inner)
            ray = np.concatenate([ray, ray])
            left = child.take(node).astype(np.int64)
            node = np.concatenate([left, left + 1])
        best_p[best_p == none] = -1
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
