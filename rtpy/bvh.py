"""Bounding volume hierarchy (BVH): the closest hit without testing every object.

A ray that misses a box cannot hit anything inside it. A BVH is a binary tree of
axis-aligned bounding boxes (AABBs): each leaf holds a few objects, each interior
node the box around its two children. A ray tests the root's box, then only the
children whose boxes it enters, so it visits about log2(n) levels instead of n
objects. The tree is built top down, each node's objects split in two where the
surface area heuristic (SAH) predicts the fewest tests per ray.

Conventions:

- Boxes are closed: [x0, x1] x [y0, y1] x [z0, z1]; a point on a face is inside.
- Objects are hit strictly inside the ray interval (t_min < t < t_max), as in
  Scene. Box tests accept the closed interval (t_min <= t <= t_max): a box test
  may let through a ray that then misses every object, never the other way round.
- The result is exactly that of testing every object in list order
  (Scene.find_intersection_brute_force): the smallest t, and among objects hit at
  the same t the one earliest in the list. The floats are the objects' own, so
  they are bit-identical too.
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
    from .hittable import Hittable
    from .ray import Ray

BOX_PADDING = 1e-9
ROUNDING_MARGIN = 1e-8
LEAF_SIZE = 4  # at most this many objects in a leaf
TRAVERSAL_COST = 2.0  # cost of visiting a node, in units of one object's hit test


class AABB:
    """Axis-aligned box [x0, x1] x [y0, y1] x [z0, z1], corners stored as plain floats."""

    __slots__ = ("x0", "y0", "z0", "x1", "y1", "z1")

    def __init__(self, lo: Vec3, hi: Vec3) -> None:
        """The box with corners lo (smallest coordinates) and hi (largest)."""
        self.x0, self.y0, self.z0 = lo.e0, lo.e1, lo.e2
        self.x1, self.y1, self.z1 = hi.e0, hi.e1, hi.e2

    @staticmethod
    def from_points(*points: Vec3) -> AABB:
        """The smallest box containing the points."""
        return AABB(
            Vec3(min(p.e0 for p in points), min(p.e1 for p in points), min(p.e2 for p in points)),
            Vec3(max(p.e0 for p in points), max(p.e1 for p in points), max(p.e2 for p in points)),
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
            self.x0 <= p.e0 <= self.x1 and self.y0 <= p.e1 <= self.y1 and self.z0 <= p.e2 <= self.z1
        )

    def centroid(self) -> tuple[float, float, float]:
        return (
            0.5 * (self.x0 + self.x1),
            0.5 * (self.y0 + self.y1),
            0.5 * (self.z0 + self.z1),
        )

    def entry(
        self,
        ox: float,
        oy: float,
        oz: float,
        dx: float,
        dy: float,
        dz: float,
        t_min: float,
        t_max: float,
    ) -> float | None:
        """The slab test: where the ray o + t d enters the box within [t_min, t_max].

        Returns the smallest t in [t_min, t_max] with o + t d in the box (t_min
        itself when the ray starts inside), or None when there is none. The box is
        the intersection of three slabs, x0 <= x <= x1 and so on; the ray is inside
        the x slab for t between (x0 - ox) / dx and (x1 - ox) / dx, and inside the
        box where the three slabs' intervals and [t_min, t_max] overlap. A ray
        parallel to a slab (d = 0 on that axis) is inside it for every t or none.

        The three axes run the same code, written out: a loop over the axes makes
        this, the BVH's most frequent call, about twice as slow.
        """
        if dx == 0.0:
            if ox < self.x0 or ox > self.x1:
                return None
        else:
            t_lo = (self.x0 - ox) / dx
            t_hi = (self.x1 - ox) / dx
            if t_lo > t_hi:  # the ray runs toward -x
                t_lo, t_hi = t_hi, t_lo
            if t_lo > t_min:
                t_min = t_lo
            if t_hi < t_max:
                t_max = t_hi
            if t_min > t_max:
                return None
        if dy == 0.0:
            if oy < self.y0 or oy > self.y1:
                return None
        else:
            t_lo = (self.y0 - oy) / dy
            t_hi = (self.y1 - oy) / dy
            if t_lo > t_hi:
                t_lo, t_hi = t_hi, t_lo
            if t_lo > t_min:
                t_min = t_lo
            if t_hi < t_max:
                t_max = t_hi
            if t_min > t_max:
                return None
        if dz == 0.0:
            if oz < self.z0 or oz > self.z1:
                return None
        else:
            t_lo = (self.z0 - oz) / dz
            t_hi = (self.z1 - oz) / dz
            if t_lo > t_hi:
                t_lo, t_hi = t_hi, t_lo
            if t_lo > t_min:
                t_min = t_lo
            if t_hi < t_max:
                t_max = t_hi
            if t_min > t_max:
                return None
        return t_min

    def hit(self, ray: Ray, t_min: float, t_max: float) -> bool:
        """True when the ray passes through the box for some t in [t_min, t_max]."""
        o, d = ray.origin, ray.direction
        return self.entry(o.e0, o.e1, o.e2, d.e0, d.e1, d.e2, t_min, t_max) is not None


class BVHNode:
    """A box and either two children (interior node) or a few objects (leaf).

    `items` holds a leaf's objects with their positions in the scene's list, as
    (index, object) pairs; it is None for an interior node.
    """

    __slots__ = ("box", "left", "right", "items")

    def __init__(
        self,
        box: AABB,
        left: BVHNode | None = None,
        right: BVHNode | None = None,
        items: list[tuple[int, Hittable]] | None = None,
    ) -> None:
        self.box = box
        self.left = left
        self.right = right
        self.items = items


class BVH:
    """A bounding volume hierarchy over a list of hittables.

    Built once from the list; it does not see later changes to the list (Scene
    rebuilds it). Objects whose bounding_box() is None or not finite (unbounded
    shapes) are kept out of the tree and tested on every ray.

    margin  how much every object's box is grown; None: ROUNDING_MARGIN times the
            largest coordinate magnitude of all the boxes
    """

    def __init__(self, objects: Sequence[Hittable], margin: float | None = None) -> None:
        self.unbounded: list[tuple[int, Hittable]] = []
        bounded: list[tuple[int, Hittable, AABB]] = []
        for index, obj in enumerate(objects):
            box = obj.bounding_box()
            if box is None or not box.is_finite():
                self.unbounded.append((index, obj))
            else:
                bounded.append((index, obj, box))
        if margin is None:
            margin = ROUNDING_MARGIN * max((box.magnitude() for _, _, box in bounded), default=0.0)
        bounded = [(index, obj, box.grown(margin)) for index, obj, box in bounded]
        self.root: BVHNode | None = _build(bounded) if bounded else None

    def closest_hit(self, ray: Ray, t_min: float, t_max: float) -> tuple[Hittable, float] | None:
        """(object, t) of the closest hit with t_min < t < t_max, ties going to the
        object earliest in the list; None when nothing is hit.

        Depth first with a stack of (node, t where the ray enters its box); the
        nearer child is visited first, and boxes are tested against [t_min, best_t],
        so every hit found shrinks the part of the ray still to be searched.
        """
        o, d = ray.origin, ray.direction
        ox, oy, oz, dx, dy, dz = o.e0, o.e1, o.e2, d.e0, d.e1, d.e2
        best_t, best_index, best_obj = t_max, -1, None
        # The bound passed to hit_t. Once something is hit it is the next float
        # above best_t, so that a hit at the same t still comes back and the list
        # index can decide. (hit_t with a smaller t_max returns the same t or None.)
        limit = t_max
        for index, obj in self.unbounded:
            t = obj.hit_t(ray, t_min, limit)
            if t is not None and (t, index) < (best_t, best_index):
                best_t, best_index, best_obj = t, index, obj
                limit = math.nextafter(t, math.inf)
        root = self.root
        entry = None if root is None else root.box.entry(ox, oy, oz, dx, dy, dz, t_min, best_t)
        stack: list[tuple[BVHNode, float]] = [] if entry is None else [(root, entry)]
        while stack:
            node, entry = stack.pop()
            if entry > best_t:
                continue  # a hit found since this node was pushed is closer than its box
            if node.items is not None:
                for index, obj in node.items:  # as for the unbounded objects above
                    t = obj.hit_t(ray, t_min, limit)
                    if t is not None and (t, index) < (best_t, best_index):
                        best_t, best_index, best_obj = t, index, obj
                        limit = math.nextafter(t, math.inf)
                continue
            left, right = node.left, node.right
            left_entry = left.box.entry(ox, oy, oz, dx, dy, dz, t_min, best_t)
            right_entry = right.box.entry(ox, oy, oz, dx, dy, dz, t_min, best_t)
            # Push the farther child first so that the nearer one is visited first:
            # its hits shrink best_t, and the farther box may then be skipped.
            if left_entry is None:
                if right_entry is not None:
                    stack.append((right, right_entry))
            elif right_entry is None:
                stack.append((left, left_entry))
            elif left_entry <= right_entry:
                stack.append((right, right_entry))
                stack.append((left, left_entry))
            else:
                stack.append((left, left_entry))
                stack.append((right, right_entry))
        if best_obj is None:
            return None
        return best_obj, best_t

    def any_hit(
        self, ray: Ray, t_min: float, t_max: float, ignore: Hittable | None = None
    ) -> bool:
        """True if some object other than `ignore` is hit with t_min < t < t_max."""
        for _, obj in self.unbounded:
            if obj is not ignore and obj.hit_t(ray, t_min, t_max) is not None:
                return True
        o, d = ray.origin, ray.direction
        ox, oy, oz, dx, dy, dz = o.e0, o.e1, o.e2, d.e0, d.e1, d.e2
        stack = [] if self.root is None else [self.root]
        while stack:
            node = stack.pop()
            if node.box.entry(ox, oy, oz, dx, dy, dz, t_min, t_max) is None:
                continue
            if node.items is None:
                stack.append(node.right)
                stack.append(node.left)
            else:
                for _, obj in node.items:
                    if obj is not ignore and obj.hit_t(ray, t_min, t_max) is not None:
                        return True
        return False

    def depth(self) -> int:
        """Number of levels (a lone leaf is 1; an empty tree 0)."""

        def levels(node: BVHNode | None) -> int:
            if node is None:
                return 0
            if node.items is not None:
                return 1
            return 1 + max(levels(node.left), levels(node.right))

        return levels(self.root)


def _build(items: list[tuple[int, Hittable, AABB]]) -> BVHNode:
    """The subtree over `items` (index, object, box).

    The surface area heuristic: a ray that passes through a box passes through a
    box inside it with a probability of about the ratio of their surface areas.
    So a leaf costs n object tests per ray that reaches it, and a split costs
    TRAVERSAL_COST + (area(left) * n_left + area(right) * n_right) / area. A node
    with more than LEAF_SIZE objects is always split, at its cheapest split.
    """
    box = items[0][2]
    for _, _, other in items[1:]:
        box = box.union(other)
    n = len(items)
    if n == 1:
        return BVHNode(box, items=[(items[0][0], items[0][1])])
    weighted_area, ordered, k = _cheapest_split(items)
    area = box.surface_area()
    # leaf cost <= split cost, both multiplied by area (which may be 0 for a flat box)
    if n <= LEAF_SIZE and n * area <= TRAVERSAL_COST * area + weighted_area:
        return BVHNode(box, items=[(index, obj) for index, obj, _ in items])
    return BVHNode(box, left=_build(ordered[:k]), right=_build(ordered[k:]))


def _cheapest_split(
    items: list[tuple[int, Hittable, AABB]],
) -> tuple[float, list[tuple[int, Hittable, AABB]], int]:
    """(weighted_area, ordered, k): the split into ordered[:k] and ordered[k:] with
    the least weighted_area = area(left) * k + area(right) * (n - k), trying every k
    on each of the three axes with the items sorted by their centroids along it."""
    n = len(items)
    best: tuple[float, list[tuple[int, Hittable, AABB]], int] = (math.inf, items, n // 2)
    centroids = [item[2].centroid() for item in items]
    for axis in range(3):
        order = sorted(range(n), key=lambda i: centroids[i][axis])
        ordered = [items[i] for i in order]
        right_area = [0.0] * n  # right_area[k]: surface area of the box around ordered[k:]
        box = ordered[-1][2]
        for k in range(n - 1, 0, -1):
            box = box.union(ordered[k][2])
            right_area[k] = box.surface_area()
        box = ordered[0][2]  # the box around ordered[:k]
        for k in range(1, n):
            weighted_area = box.surface_area() * k + right_area[k] * (n - k)
            if weighted_area < best[0]:
                best = (weighted_area, ordered, k)
            box = box.union(ordered[k][2])
    return best
