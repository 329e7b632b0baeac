"""Building a BVH with numpy: a million boxes in about a second, as flat arrays.

rtpy/bvh.py's readable builder tries every split of every node in Python, about 200
microseconds a primitive. This one is HLBVH (Pantaleoni and Luebke 2010, "HLBVH:
hierarchical LBVH construction for real-time ray tracing of dynamic geometry", in the
simpler form of Garanzha, Pantaleoni and McAllister 2011, "Simpler and faster HLBVH
with work queues"), written as whole-array operations:

1. Morton codes. Each box's centroid is quantized to a 1024^3 grid over the
   centroids' bounds and its three 10-bit coordinates are interleaved into one
   30-bit code (x in the highest bit of each triple). Sorted by code, the primitives
   follow a Z-shaped curve, so primitives near in space are near in the order.
2. Clusters. Primitives whose codes share their top CLUSTER_BITS bits lie in one
   cell of a 64^3 grid; each cell's run of the sorted order is a cluster.
3. The top of the tree by the surface area heuristic (SAH), over the clusters: each
   node's clusters are split where BINS planes per axis predict the fewest
   ray-box tests, area(left) * n_left + area(right) * n_right, until every node holds
   one cluster. All nodes of a level are split at once.
4. The bottom of the tree within each cluster by its codes (LBVH, Lauterbach et al.
   2009, "Fast BVH construction on GPUs"): a node's run of codes is split where its
   highest differing bit changes, the spatial middle of the cell along that bit's
   axis, until a node holds at most leaf_size primitives.
5. The boxes, from the leaves up: a leaf's box is the union of its primitives'
   boxes, a node's the union of its children's, so every box holds its primitives'
   boxes exactly (the boxes given should already cover rounding: see rtpy/bvh.py).

The result is a Tree (rtpy.bvh.Tree): the children of an inner node are adjacent.
"""

from __future__ import annotations

import numpy as np

from . import bvh
from .bvh import Tree

CLUSTER_BITS = 18  # of the 30 bits of a code: a cluster is a cell of a 64^3 grid
BINS = 12  # SAH planes per axis and node: BINS - 1 between BINS bins


def build_tree(lo: np.ndarray, hi: np.ndarray, leaf_size: int | None = None) -> Tree:
    """The tree over K >= 1 boxes lo[i] .. hi[i] ((K, 3) arrays of finite floats),
    leaves of at most leaf_size (default rtpy.bvh.LEAF_SIZE) primitives."""
    leaf_size = bvh.LEAF_SIZE if leaf_size is None else leaf_size
    # The work is done on columns, (3, K): numpy reduces, gathers and scans along the
    # contiguous axis several times faster than over the rows of a (K, 3) array. A
    # (K, 3) view of such columns (Mesh's boxes) is taken as it is, without a copy.
    lo_t = np.ascontiguousarray(np.asarray(lo, dtype=np.float64).T)
    hi_t = np.ascontiguousarray(np.asarray(hi, dtype=np.float64).T)
    k = lo_t.shape[1]
    if k == 0:
        raise ValueError("a tree needs at least one box")
    # Every temporary of a million boxes is new memory, which the kernel hands out a
    # page at a time (about half a millisecond a MB): they are let go when done.
    centroid = lo_t + hi_t
    centroid *= 0.5
    codes = morton_codes(centroid.T)
    del centroid
    order = np.argsort(codes, kind="stable")
    codes = codes.take(order)
    # Clusters: runs of equal top bits.
    first = np.flatnonzero(np.diff(codes >> (30 - CLUSTER_BITS))) + 1
    c_start = np.concatenate([[0], first]).astype(np.int64)
    c_end = np.concatenate([first, [k]]).astype(np.int64)
    c_lo = np.minimum.reduceat(lo_t.take(order, axis=1), c_start, axis=1)
    c_hi = np.maximum.reduceat(hi_t.take(order, axis=1), c_start, axis=1)
    nodes = _Nodes(k, len(c_start))
    c_perm = _top_levels(nodes, c_lo, c_hi, c_end - c_start, leaf_size)
    # The primitives in the clusters' final order; node ranges over clusters become
    # ranges over primitives.
    size = (c_end - c_start).take(c_perm)
    offset = np.concatenate([[0], np.cumsum(size)])
    positions = _ranges(c_start.take(c_perm), size)
    order = order.take(positions)
    # Keys in the final order: the cluster's rank above its code, so sorted throughout.
    keys = np.repeat(np.arange(len(c_perm), dtype=np.int64) << 30, size)
    keys |= codes.take(positions)
    del codes, positions
    nodes.to_primitives(offset)
    _bottom_levels(nodes, keys, leaf_size)
    return nodes.tree(lo_t, hi_t, order)


def morton_codes(points: np.ndarray) -> np.ndarray:
    """(K,) int64 30-bit Morton codes of points (K, 3) on a 1024^3 grid over their
    bounds (an axis along which all points agree gets coordinate 0)."""
    codes = np.zeros(len(points), dtype=np.int64)
    for i in range(3):  # column by column: x's bits highest in each triple
        column = points[:, i]
        low, high = column.min(), column.max()
        extent = high - low
        q = column - low
        q *= 1024.0 / extent if extent > 0.0 else 0.0
        cell = q.astype(np.int64)
        np.clip(cell, 0, 1023, out=cell)
        codes |= _spread(cell) << (2 - i)
    return codes


def _spread(x: np.ndarray) -> np.ndarray:
    """The 10 bits of x moved to every third bit (bit i to bit 3i)."""
    x = x | (x << 16)
    x &= 0x030000FF
    for shift, mask in ((8, 0x0300F00F), (4, 0x030C30C3), (2, 0x09249249)):
        x |= x << shift
        x &= mask
    return x


def _ranges(start: np.ndarray, length: np.ndarray) -> np.ndarray:
    """The concatenation of arange(s, s + n) for each (s, n)."""
    total = int(length.sum())
    if total == 0:
        return np.zeros(0, dtype=np.int64)
    ends = np.cumsum(length)
    shift = np.repeat(start - (ends - length), length)
    return shift + np.arange(total, dtype=np.int64)


def _scan(op, a: np.ndarray) -> np.ndarray:
    """op.accumulate(a, axis=1) of a (3, BINS, S) array, a bin at a time: twenty
    times faster than numpy's accumulate, which scans element by element."""
    out = np.empty_like(a)
    out[:, 0] = a[:, 0]
    for i in range(1, a.shape[1]):
        op(out[:, i - 1], a[:, i], out=out[:, i])
    return out


def _area(lo: np.ndarray, hi: np.ndarray) -> np.ndarray:
    """The surface areas of boxes given as columns (3, ...)."""
    e = np.maximum(hi - lo, 0.0)
    return 2.0 * (e[0] * e[1] + e[1] * e[2] + e[2] * e[0])


class _Nodes:
    """The nodes made so far: node i covers start[i] .. end[i] (clusters during the
    top levels, primitives after to_primitives); an inner node's children are
    child[i] and child[i] + 1 (-1: a leaf), split along axis[i]. A tree over K
    primitives has at most 2 K - 1 nodes (int32, as the Tree's arrays)."""

    def __init__(self, k: int, root_end: int) -> None:
        self.start = np.zeros(2 * k, dtype=np.int32)
        self.end = np.zeros(2 * k, dtype=np.int32)
        self.child = np.full(2 * k, -1, dtype=np.int32)
        self.axis = np.zeros(2 * k, dtype=np.int8)
        self.end[0], self.n = root_end, 1
        self.splits: list[np.ndarray] = []  # per level: the nodes split then

    def split(self, ids: np.ndarray, middle: np.ndarray, axis: np.ndarray) -> np.ndarray:
        """Give nodes `ids` the children start..middle and middle..end; returns the
        children's ids, as (left, right) pairs in one (2 S,) array."""
        first = self.n + 2 * np.arange(len(ids), dtype=np.int64)
        self.child[ids], self.axis[ids] = first, axis
        self.start[first], self.end[first] = self.start[ids], middle
        self.start[first + 1], self.end[first + 1] = middle, self.end[ids]
        self.n += 2 * len(ids)
        self.splits.append(ids)
        return np.stack([first, first + 1], axis=1).ravel()

    def to_primitives(self, offset: np.ndarray) -> None:
        """Ranges over clusters made ranges over primitives (offset: the first
        primitive of each position of the clusters' order)."""
        n = self.n
        self.start[:n], self.end[:n] = offset[self.start[:n]], offset[self.end[:n]]

    def tree(self, lo_t, hi_t, order) -> Tree:
        """The Tree, given the primitives' boxes as columns (3, K) and their final
        order."""
        n = self.n
        start, end, child = self.start[:n], self.end[:n], self.child[:n]
        leaf = child < 0
        count = np.where(leaf, end - start, 0)
        child = np.where(leaf, start, child)
        lo = np.empty((n, 3))
        hi = np.empty((n, 3))
        # A leaf's box: the union of its primitives' boxes, taken for all leaves at
        # once as the union of their first, second, ... primitive's (a leaf's last
        # one again past its count).
        leaves = np.flatnonzero(leaf)
        first, last = start.take(leaves), end.take(leaves) - 1
        for j in range(int((last - first).max()) + 1):
            prims = order.take(np.minimum(first + j, last))
            box_lo, box_hi = lo_t.take(prims, axis=1), hi_t.take(prims, axis=1)
            if j == 0:
                leaf_lo, leaf_hi = box_lo, box_hi
            else:
                np.minimum(leaf_lo, box_lo, out=leaf_lo)
                np.maximum(leaf_hi, box_hi, out=leaf_hi)
        lo[leaves], hi[leaves] = leaf_lo.T, leaf_hi.T
        for ids in reversed(self.splits):  # children before their parents
            c = child[ids]
            lo[ids] = np.minimum(lo[c], lo[c + 1])
            hi[ids] = np.maximum(hi[c], hi[c + 1])
        axis = self.axis[:n].copy()
        return Tree(lo, hi, child, count, axis, order)


def _top_levels(nodes: _Nodes, c_lo, c_hi, c_count, leaf_size: int) -> np.ndarray:
    """Split the root's clusters (their boxes as columns c_lo, c_hi (3, M)) by binned
    SAH, level by level, until every node holds one cluster or at most leaf_size
    primitives; returns the clusters' final order (every node's clusters adjacent in
    it)."""
    m = c_lo.shape[1]
    perm = np.arange(m, dtype=np.int64)
    centroid = 0.5 * (c_lo + c_hi)
    ids = np.zeros(1, dtype=np.int64)
    start, end = np.zeros(1, dtype=np.int64), np.full(1, m, dtype=np.int64)
    while ids.size:
        # Node primitive counts are taken through the current order.
        counts_in_order = np.concatenate([[0], np.cumsum(c_count.take(perm))])
        n_prims = counts_in_order[end] - counts_in_order[start]
        go = (end - start >= 2) & (n_prims > leaf_size)
        ids, start, end = ids[go], start[go], end[go]
        if ids.size == 0:
            break
        s = len(ids)
        length = end - start
        pos = _ranges(start, length)
        member = perm.take(pos)
        node = np.repeat(np.arange(s), length)
        first = np.concatenate([[0], np.cumsum(length)[:-1]])
        cc = centroid.take(member, axis=1)
        nmin = np.minimum.reduceat(cc, first, axis=1)
        ext = np.maximum.reduceat(cc, first, axis=1) - nmin
        weight = c_count.take(member).astype(np.float64)
        m_lo, m_hi = c_lo.take(member, axis=1), c_hi.take(member, axis=1)
        # Per axis, bin and node (the nodes innermost, so the scans over the bins
        # run over whole rows): the clusters' count and box, then the cost of each
        # plane between bins.
        cost = np.full((3, BINS - 1, s), np.inf)
        bins = np.empty((3, len(member)), dtype=np.int64)
        for axis in range(3):
            scale = np.divide(BINS, ext[axis], out=np.zeros(s), where=ext[axis] > 0.0)
            b = ((cc[axis] - nmin[axis, node]) * scale[node]).astype(np.int64)
            np.clip(b, 0, BINS - 1, out=b)
            bins[axis] = b
            key = b * s + node
            b_lo = np.full((3, BINS * s), np.inf)
            b_hi = np.full((3, BINS * s), -np.inf)
            for i in range(3):
                np.minimum.at(b_lo[i], key, m_lo[i])
                np.maximum.at(b_hi[i], key, m_hi[i])
            n = np.bincount(key, weights=weight, minlength=BINS * s).reshape(BINS, s)
            b_lo, b_hi = b_lo.reshape(3, BINS, s), b_hi.reshape(3, BINS, s)
            n_left = np.cumsum(n, axis=0)[:-1]
            left = _area(_scan(np.minimum, b_lo), _scan(np.maximum, b_hi))
            right = _area(
                _scan(np.minimum, b_lo[:, ::-1])[:, ::-1], _scan(np.maximum, b_hi[:, ::-1])[:, ::-1]
            )
            total = n.sum(axis=0)
            with np.errstate(invalid="ignore"):  # empty sides: inf * 0
                c = left[:-1] * n_left + right[1:] * (total - n_left)
            cost[axis] = np.where((n_left > 0) & (n_left < total), c, np.inf)
        flat = cost.reshape(-1, s)
        best = flat.argmin(axis=0)
        axis_of, plane = np.divmod(best, BINS - 1)
        found = np.isfinite(flat[best, np.arange(s)])
        # Right of the chosen plane; where no plane separates (all centroids in one
        # bin), the second half of the node's clusters.
        right_side = bins[axis_of[node], np.arange(len(member))] > plane[node]
        halves = (pos - start[node]) >= (length // 2)[node]
        right_side = np.where(found[node], right_side, halves)
        sort = np.lexsort((right_side, node))
        perm[pos] = member.take(sort)
        middle = start + (length - np.bincount(node, weights=right_side, minlength=s)).astype(
            np.int64
        )
        ids = nodes.split(ids, middle, axis_of.astype(np.int8))
        start, end = nodes.start[ids], nodes.end[ids]
    return perm


def _bottom_levels(nodes: _Nodes, keys: np.ndarray, leaf_size: int) -> None:
    """Split every leaf of more than leaf_size primitives where the highest bit of
    its keys changes (or in the middle where all keys are equal), level by level."""
    ids = np.flatnonzero(nodes.child[: nodes.n] < 0)
    while ids.size:
        start, end = nodes.start[ids], nodes.end[ids]
        go = end - start > leaf_size
        ids, start, end = ids[go], start[go], end[go]
        if ids.size == 0:
            break
        a, b = keys.take(start), keys.take(end - 1)
        diff = a ^ b
        # the highest differing bit: exact through float64, the keys are < 2^48
        bit = np.frexp(diff.astype(np.float64))[1] - 1
        same = diff == 0
        bit = np.where(same, 0, bit)
        target = (b >> bit) << bit
        middle = np.searchsorted(keys, target, side="left")
        middle = np.where(same, (start + end) // 2, middle)
        axis = np.where(same | (bit >= 30), 0, 2 - bit % 3).astype(np.int8)
        ids = nodes.split(ids, middle, axis)
