"""Bounding volume hierarchy (BVH): the closest hit without testing every object.

A ray that misses a box cannot hit anything inside it. A BVH is a binary tree of
axis-aligned bounding boxes (AABBs): each leaf holds a few objects, each interior
node the box around its two children. A ray tests the root's box, then only the
children whose boxes it enters, so it visits about log2(n) levels instead of n
objects.

The tree is stored flat (Tree): arrays of boxes, children and leaves, which both
backends search and which travel to worker processes as they are. It is built by
rtpy/_bvh_build.py (numpy: Morton codes, then the surface area heuristic, a million
boxes in about a second) or, for reading, by build_readable below: top down, each
node's objects split where the surface area heuristic (SAH) predicts the fewest
tests per ray. Both trees give the same answers.

Conventions:

- Boxes are closed: [x0, x1] x [y0, y1] x [z0, z1]; a point on a face is inside.
- Objects are hit strictly inside the ray interval (t_min < t < t_max), as in
  Scene. Box tests accept the closed interval (t_min <= t <= t_max): a box test
  may let through a ray that then misses every object, never the other way round.
- The result is exactly that of testing every object in list order (a Scene below
  its bvh_min_objects): the smallest t, and among objects hit at the same t
  the one earliest in the list. The floats are the objects' own, so they are
  bit-identical too.
- Boxes are a little larger than the objects in them, because the box test and
  an object's hit test round differently. A shape's bounding_box() is padded by
  BOX_PADDING of its coordinates' size, which gives flat shapes (an axis-aligned
  quad) a thickness; the BVH then grows every box by ROUNDING_MARGIN of the whole
  scene's size. That covers the rounding of the objects' hit tests (a hit point a
  few ulps outside a quad's edge, a triangle hit by a ray at a grazing angle) for
  rays that start within many scene sizes of the scene. The hit tests must report
  points on the object, up to rounding: Triangle treats rays within 1e-6 of its
  plane as parallel for that reason.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from typing import TYPE_CHECKING

from .vec3 import Vec3

if TYPE_CHECKING:
    from .hit_info import HitInfo
    from .hittable import Hittable
    from .ray import Ray

BOX_PADDING = 1e-9
ROUNDING_MARGIN = 1e-8
LEAF_SIZE = 4  # at most this many objects in a leaf
TRAVERSAL_COST = 2.0  # cost of visiting a node, in units of one object's hit test
READABLE_MAX = 32  # BVH builds trees of fewer objects with build_readable (as fast there)


class AABB:
    """Axis-aligned box [x0, x1] x [y0, y1] x [z0, z1], corners stored as plain floats."""

    __slots__ = ("x0", "y0", "z0", "x1", "y1", "z1")

    def __init__(self, lo: Vec3, hi: Vec3) -> None:
        """The box with corners lo (smallest coordinates) and hi (largest)."""
        self.x0, self.y0, self.z0 = lo.x(), lo.y(), lo.z()
        self.x1, self.y1, self.z1 = hi.x(), hi.y(), hi.z()

    @staticmethod
    def from_points(*points: Vec3) -> AABB:
        """The smallest box containing the points."""
        return AABB(
            Vec3(
                min(p.x() for p in points), min(p.y() for p in points), min(p.z() for p in points)
            ),
            Vec3(
                max(p.x() for p in points), max(p.y() for p in points), max(p.z() for p in points)
            ),
        )

    @property
    def lo(self) -> Vec3:
        return Vec3(self.x0, self.y0, self.z0)

    @property
    def hi(self) -> Vec3:
        return Vec3(self.x1, self.y1, self.z1)

    def __repr__(self) -> str:
        return f"AABB({self.lo!r}, {self.hi!r})"

    def union(self, other: AABB) -> AABB:
        """The smallest box containing both boxes."""
        return AABB(
            Vec3(min(self.x0, other.x0), min(self.y0, other.y0), min(self.z0, other.z0)),
            Vec3(max(self.x1, other.x1), max(self.y1, other.y1), max(self.z1, other.z1)),
        )

    def grown(self, margin: float) -> AABB:
        """The box moved out by `margin` on every side."""
        return AABB(
            Vec3(self.x0 - margin, self.y0 - margin, self.z0 - margin),
            Vec3(self.x1 + margin, self.y1 + margin, self.z1 + margin),
        )

    def magnitude(self) -> float:
        """The largest absolute coordinate of the box: the scale of its rounding errors."""
        return max(
            abs(self.x0), abs(self.y0), abs(self.z0), abs(self.x1), abs(self.y1), abs(self.z1)
        )

    def padded(self) -> AABB:
        """The box grown by BOX_PADDING times its magnitude (at least one ulp) on every
        side, so that no side has zero thickness and the rounding of the corners'
        arithmetic (center - radius, ...) cannot leave a point of the shape outside."""
        m = self.magnitude()
        return self.grown(max(BOX_PADDING * m, math.ulp(m)))

    def surface_area(self) -> float:
        """The area of the box's six faces (the SAH's measure of how often rays hit it)."""
        dx, dy, dz = self.x1 - self.x0, self.y1 - self.y0, self.z1 - self.z0
        return 2.0 * (dx * dy + dy * dz + dz * dx)

    def is_finite(self) -> bool:
        """False for a box with an infinite or nan coordinate (an unbounded shape)."""
        return all(math.isfinite(c) for c in (self.x0, self.y0, self.z0, self.x1, self.y1, self.z1))

    def contains(self, p: Vec3) -> bool:
        return (
            self.x0 <= p.x() <= self.x1
            and self.y0 <= p.y() <= self.y1
            and self.z0 <= p.z() <= self.z1
        )

    def centroid(self) -> tuple[float, float, float]:
        return (
            0.5 * (self.x0 + self.x1),
            0.5 * (self.y0 + self.y1),
            0.5 * (self.z0 + self.z1),
        )


class Tree:
    """A BVH as flat arrays, the form both backends search and workers receive.

    Node 0 is the root; node i has the box lo[i] .. hi[i]. An inner node
    (count[i] == 0) has the children child[i] and child[i] + 1, its primitives
    split along axis[i] (0, 1, 2: x, y, z), the left child's lower along it. A leaf
    holds the count[i] primitives order[child[i] : child[i] + count[i]] (indices
    into the list the tree was built over). numpy arrays: lo, hi (n, 3) float64;
    child, count (n,) int32; axis (n,) int8; order (K,) int.
    """

    def __init__(self, lo, hi, child, count, axis, order) -> None:
        self.lo, self.hi, self.child, self.count, self.axis = lo, hi, child, count, axis
        self.order = order

    def __len__(self) -> int:
        """The number of nodes."""
        return len(self.count)

    def depth(self) -> int:
        """The number of levels (a lone leaf is 1)."""
        levels, frontier = 0, [0]
        child, count = self.child.tolist(), self.count.tolist()
        while frontier:
            levels += 1
            frontier = [c for i in frontier if count[i] == 0 for c in (child[i], child[i] + 1)]
        return levels


class BVH:
    """A bounding volume hierarchy over a list of hittables.

    Built once from the list; it does not see later changes to the list (Scene
    rebuilds it). Objects whose bounding_box() is None or not finite (unbounded
    shapes) are kept out of the tree; the search tests them first on every ray.

    margin   how much every object's box is grown; None: ROUNDING_MARGIN times the
             largest coordinate magnitude of all the boxes
    readable True: built by build_readable (this module, plain Python); False: by
             rtpy._bvh_build (numpy, hundreds of times faster on large lists); None:
             the readable builder below READABLE_MAX objects, where it is as fast
    """

    def __init__(
        self, objects: Sequence[Hittable], margin: float | None = None, readable: bool | None = None
    ) -> None:
        self.objects = list(objects)
        self.unbounded: list[int] = []
        bounded: list[int] = []
        boxes: list[AABB] = []
        for index, obj in enumerate(objects):
            box = obj.bounding_box()
            if box is None or not box.is_finite():
                self.unbounded.append(index)
            else:
                bounded.append(index)
                boxes.append(box)
        if margin is None:
            margin = ROUNDING_MARGIN * max((box.magnitude() for box in boxes), default=0.0)
        boxes = [box.grown(margin) for box in boxes]
        self.tree: Tree | None = None
        if boxes:
            if readable is None:
                readable = len(boxes) < READABLE_MAX
            tree = build_readable(boxes) if readable else _build_fast(boxes)
            # positions among the bounded objects -> indices in `objects`
            tree.order = _take(bounded, tree.order)
            self.tree = tree
        self._lists: tuple | None = None

    @classmethod
    def over_tree(cls, objects: Sequence[Hittable], tree: Tree) -> BVH:
        """The BVH over objects (every one bounded) whose tree is already built."""
        bvh = cls.__new__(cls)
        bvh.objects, bvh.unbounded, bvh.tree, bvh._lists = objects, [], tree, None
        return bvh

    def __getstate__(self) -> dict:
        # The search's lists are made again where they are used, from the arrays.
        return {**self.__dict__, "_lists": None}

    def lists(self) -> tuple:
        """The tree as Python lists, which the search reads much faster than numpy
        arrays: (start, bounds, child, count, axis, order), bounds[i] the tuple
        (x0, y0, z0, x1, y1, z1) of node i's box, start the nodes a search starts
        from, the last first. The unbounded objects are one more leaf, last, with an
        infinite box. Made on the first search."""
        if self._lists is None:
            bounds, child, count, axis, order, start = [], [], [], [], [], []
            t = self.tree
            if t is not None:
                import numpy as np

                bounds = list(map(tuple, np.concatenate([t.lo, t.hi], axis=1).tolist()))
                child, count = t.child.tolist(), t.count.tolist()
                axis, order, start = t.axis.tolist(), t.order.tolist(), [0]
            if self.unbounded:
                inf = math.inf
                start.append(len(bounds))
                bounds.append((-inf, -inf, -inf, inf, inf, inf))
                child.append(len(order))
                count.append(len(self.unbounded))
                axis.append(0)
                order = order + self.unbounded
            self._lists = (start, bounds, child, count, axis, order)
        return self._lists

    def closest_hit(self, ray: Ray, t_min: float, t_max: float) -> tuple[int, float] | None:
        """(index, t) of the closest hit with t_min < t < t_max, ties going to the
        object earliest in the list; None when nothing is hit."""
        return self._search(ray, t_min, t_max, None, False)

    def find_intersection(self, ray: Ray, interval) -> HitInfo | None:
        """As Scene.find_intersection: the closest hit inside the interval, or None."""
        found = self.closest_hit(ray, interval.min, interval.max)
        if found is None:
            return None
        index, t = found
        return self.objects[index].hit_info(ray, t)

    def any_hit(self, ray: Ray, t_min: float, t_max: float, ignore: Hittable | None = None) -> bool:
        """True if some object other than `ignore` is hit with t_min < t < t_max."""
        return self._search(ray, t_min, t_max, ignore, True) is not None

    def _search(
        self, ray: Ray, t_min: float, t_max: float, ignore: Hittable | None, first: bool
    ) -> tuple[int, float] | None:
        """(index, t) of the closest hit with t_min < t < t_max, or with first=True
        of the first hit found; objects other than `ignore` only.

        Depth first with a stack of nodes (the unbounded objects' leaf first); of
        two children the one on the side the ray comes from along their
        split axis is visited first, and a box is tested against [t_min, best_t]
        when its node comes off the stack, so every hit found shrinks the part of
        the ray still to be searched.
        """
        objects = self.objects
        start, bounds, child, count, axis, order = self.lists()
        best_t, best_index = t_max, -1
        # The bound passed to hit_t. Once something is hit it is the next float
        # above best_t, so that a hit at the same t still comes back and the list
        # index can decide. (hit_t with a smaller t_max returns the same t or None.)
        limit = t_max
        o, d = ray.origin, ray.direction
        ox, oy, oz, dx, dy, dz = o.x(), o.y(), o.z(), d.x(), d.y(), d.z()
        # Per axis: 1 / d (inf where d = 0, see the slab test) and the positions in
        # a node's bounds (x0, y0, z0, x1, y1, z1) of the faces the ray meets first
        # (n) and last (f) along it: the low ones when d >= 0, else the high ones.
        ix = 1.0 / dx if dx != 0.0 else math.inf
        iy = 1.0 / dy if dy != 0.0 else math.inf
        iz = 1.0 / dz if dz != 0.0 else math.inf
        nx, ny, nz = (0 if ix > 0.0 else 3), (1 if iy > 0.0 else 4), (2 if iz > 0.0 else 5)
        fx, fy, fz = 3 - nx, 5 - ny, 7 - nz
        backward = (nx == 3, ny == 4, nz == 5)  # the ray runs toward -x, -y, -z
        stack = start[:]
        while stack:
            node = stack.pop()
            # The slab test. The ray is inside the box's x slab for t between
            # x0 = (near x face - ox) / dx and x1 = (far x face - ox) / dx, likewise
            # for y and z, and in the box where the three intervals and
            # [t_min, best_t] overlap. A ray parallel to a slab (1 / d = inf) gets
            # -inf .. inf inside it, an empty interval outside, and nan = 0 * inf
            # where it runs in a face's plane: nan loses every comparison, so it
            # leaves the interval as it is, as a closed box wants. Written out, not
            # as a loop over the axes or a call: this runs for every node visited.
            b = bounds[node]
            x0, x1 = (b[nx] - ox) * ix, (b[fx] - ox) * ix
            y0, y1 = (b[ny] - oy) * iy, (b[fy] - oy) * iy
            enter = x0 if x0 > t_min else t_min
            enter = y0 if y0 > enter else enter
            leave = x1 if x1 < best_t else best_t
            leave = y1 if y1 < leave else leave
            if enter > leave:
                continue  # misses the box, or meets it only outside [t_min, best_t]
            z0, z1 = (b[nz] - oz) * iz, (b[fz] - oz) * iz
            if z0 > leave or z1 < enter:
                continue
            n, c = count[node], child[node]
            if n == 0:
                if backward[axis[node]]:  # the right child, higher along the axis, first
                    stack.append(c)
                    stack.append(c + 1)
                else:
                    stack.append(c + 1)
                    stack.append(c)
                continue
            for k in range(c, c + n):
                index = order[k]
                obj = objects[index]
                if obj is ignore:
                    continue
                t = obj.hit_t(ray, t_min, limit)
                if t is not None and (t, index) < (best_t, best_index):
                    if first:
                        return index, t
                    best_t, best_index = t, index
                    limit = math.nextafter(t, math.inf)
        if best_index < 0:
            return None
        return best_index, best_t

    def depth(self) -> int:
        """Number of levels of the tree (a lone leaf is 1; an empty tree 0)."""
        return 0 if self.tree is None else self.tree.depth()


def _take(values: list[int], positions) -> object:
    """values[positions] as a numpy array (positions a numpy array)."""
    import numpy as np

    return np.asarray(values, dtype=np.int64).take(positions)


def _build_fast(boxes: list[AABB]) -> Tree:
    import numpy as np

    from ._bvh_build import build_tree

    lo = np.array([(b.x0, b.y0, b.z0) for b in boxes], dtype=np.float64)
    hi = np.array([(b.x1, b.y1, b.z1) for b in boxes], dtype=np.float64)
    return build_tree(lo, hi)


# --- the readable builder ------------------------------------------------------------


def build_readable(boxes: list[AABB]) -> Tree:
    """The tree over the boxes, top down in plain Python: each node's boxes split in
    two where the surface area heuristic predicts the fewest tests per ray.

    The surface area heuristic: a ray that passes through a box passes through a
    box inside it with a probability of about the ratio of their surface areas.
    So a leaf costs n object tests per ray that reaches it, and a split costs
    TRAVERSAL_COST + (area(left) * n_left + area(right) * n_right) / area. A node
    with more than LEAF_SIZE objects is always split, at its cheapest split.
    """
    lo: list[tuple[float, float, float]] = []
    hi: list[tuple[float, float, float]] = []
    child: list[int] = []
    count: list[int] = []
    axes: list[int] = []
    order: list[int] = []

    def new_node() -> int:
        lo.append((0.0, 0.0, 0.0))
        hi.append((0.0, 0.0, 0.0))
        child.append(0)
        count.append(0)
        axes.append(0)
        return len(lo) - 1

    def build(node: int, items: list[tuple[int, AABB]]) -> None:
        box = items[0][1]
        for _, other in items[1:]:
            box = box.union(other)
        lo[node], hi[node] = (box.x0, box.y0, box.z0), (box.x1, box.y1, box.z1)
        n = len(items)
        if n > 1:
            weighted_area, ordered, k, axis = _cheapest_split(items)
            area = box.surface_area()
            # leaf cost <= split cost, both multiplied by area (which may be 0 for a flat box)
            split = n > LEAF_SIZE or n * area > TRAVERSAL_COST * area + weighted_area
            if split:
                left = new_node()
                new_node()  # the right child, always next to the left one
                child[node], axes[node] = left, axis
                build(left, ordered[:k])
                build(left + 1, ordered[k:])
                return
        child[node], count[node] = len(order), n
        order.extend(index for index, _ in items)

    build(new_node(), list(enumerate(boxes)))
    import numpy as np

    return Tree(
        np.array(lo),
        np.array(hi),
        np.array(child, dtype=np.int32),
        np.array(count, dtype=np.int32),
        np.array(axes, dtype=np.int8),
        np.array(order, dtype=np.int64),
    )


def _cheapest_split(
    items: list[tuple[int, AABB]],
) -> tuple[float, list[tuple[int, AABB]], int, int]:
    """(weighted_area, ordered, k, axis): the split into ordered[:k] and ordered[k:]
    with the least weighted_area = area(left) * k + area(right) * (n - k), trying every
    k on each of the three axes with the items sorted by their centroids along it."""
    n = len(items)
    best: tuple[float, list[tuple[int, AABB]], int, int] = (math.inf, items, n // 2, 0)
    centroids = [box.centroid() for _, box in items]
    for axis in range(3):
        order = sorted(range(n), key=lambda i: centroids[i][axis])
        ordered = [items[i] for i in order]
        right_area = [0.0] * n  # right_area[k]: surface area of the box around ordered[k:]
        box = ordered[-1][1]
        for k in range(n - 1, 0, -1):
            box = box.union(ordered[k][1])
            right_area[k] = box.surface_area()
        box = ordered[0][1]  # the box around ordered[:k]
        for k in range(1, n):
            weighted_area = box.surface_area() * k + right_area[k] * (n - k)
            if weighted_area < best[0]:
                best = (weighted_area, ordered, k, axis)
            box = box.union(ordered[k][1])
    return best
