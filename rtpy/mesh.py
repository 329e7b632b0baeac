"""Triangle meshes: SmoothTriangle (a triangle with vertex normals), Transform (scale,
rotate, translate) and Mesh, the triangles of a mesh as one object of a scene.

A mesh is one object of the scene's list, with a BVH of its own over its triangles
(a tree of trees, as in the compiled renderers): the scene's search meets the
mesh's box, and the mesh's search its triangles. Its triangles are arrays, not
objects, until a ray tests one.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from ._checks import (
    ANGLE,
    MAX_COORDINATE,
    MIN_AREA,
    checked,
    checked_material,
    checked_point,
    checked_scales,
    checked_vector,
    point,
)
from .bvh import AABB, BOX_PADDING, BVH, ROUNDING_MARGIN, Tree
from .hit_info import HitInfo
from .hittable import Hittable
from .ray import Ray
from .triangle import Triangle
from .vec3 import Vec3, dot, unit_vector

__all__ = ["Mesh", "SmoothTriangle", "Transform"]

BLOCK = 1 << 15  # triangles whose boxes are made at a time (_boxes)


class SmoothTriangle(Triangle):
    """A Triangle shaded with the normals given at its vertices (Phong shading).

    At a hit with barycentric weights (1 - u - v, u, v) of a, b, c the shading
    normal is normalize((1 - u - v) na + u nb + v nc), turned to the side of the
    geometric normal when it points away from it. HitInfo.normal is that shading
    normal on the side the ray came from. Intersection, front_face (which side
    was hit, which side emits) and the light-sampling densities keep the geometric
    normal `normal`. Rays leaving the surface are pushed off it along hit.normal
    (ray.spawn_ray), as on every shape; a direction between the two planes may
    then meet the triangle again from behind, the usual price of shading normals.
    """

    def __init__(self, a: Vec3, b: Vec3, c: Vec3, normals: Sequence[Vec3], material) -> None:
        super().__init__(a, b, c, material)
        self._shade(normals)

    def _shade(self, normals: Sequence[Vec3]) -> None:
        na, nb, nc = normals
        for name, n in zip(("na", "nb", "nc"), normals, strict=True):
            if not _usable(n):
                raise ValueError(f"vertex normal {name} must be a finite non-zero vector")
        self.na, self.nb, self.nc = unit_vector(na), unit_vector(nb), unit_vector(nc)

    def shading_normal(self, u: float, v: float) -> Vec3:
        """The interpolated unit normal at barycentric weights u (of b), v (of c),
        on the front side (dot with `normal` >= 0)."""
        n = self.na * (1.0 - u - v) + self.nb * u + self.nc * v
        length = n.length()
        if not length > 0.0:
            return self.normal
        n = n / length
        return -n if dot(n, self.normal) < 0.0 else n

    def hit_info(self, ray: Ray, t: float) -> HitInfo:
        point = ray.at(t)
        hit = HitInfo(point, self.normal, t, True, self.material, self)
        u, v = self.surface_uv(hit)
        n = self.shading_normal(u, v)
        front_face = dot(self.normal, ray.direction) < 0.0
        return HitInfo(point, n if front_face else -n, t, front_face, self.material, self, u, v)

    def direction_pdf(self, p: Vec3, hit: HitInfo) -> float:
        flat = HitInfo(hit.point, self.normal, hit.t, hit.front_face, self.material, self)
        return super().direction_pdf(p, flat)


class Transform:
    """p -> R (S p) + translate: S scales along x, y, z; R rotates by rotate[0] degrees
    about the x axis, then rotate[1] about y, then rotate[2] about z (fixed axes,
    right-handed: counterclockwise looking down the axis toward the origin)."""

    def __init__(
        self,
        translate: Vec3 = Vec3(0.0, 0.0, 0.0),
        rotate: Vec3 = Vec3(0.0, 0.0, 0.0),
        scale: Vec3 = Vec3(1.0, 1.0, 1.0),
    ) -> None:
        self.translate = checked_point("translate", translate)
        self.scale = checked_scales("scale", scale)
        rotate = checked_vector("rotate", rotate, ANGLE)
        rows = [[1.0, 0.0, 0.0], [0.0, 1.0, 0.0], [0.0, 0.0, 1.0]]
        for axis, degrees in enumerate(rotate):
            rows = _matmul(_rotation(axis, math.radians(degrees)), rows)
        self.rows = [Vec3(*r) for r in rows]  # the rows of R

    def point(self, p: Vec3) -> Vec3:
        s = self.scale
        q = Vec3(p.x() * s.x(), p.y() * s.y(), p.z() * s.z())
        return Vec3(*(dot(r, q) for r in self.rows)) + self.translate

    def normal(self, n: Vec3) -> Vec3:
        """A normal carried along (the inverse transpose: R S^-1 n), not normalized."""
        s = self.scale
        q = Vec3(n.x() / s.x(), n.y() / s.y(), n.z() / s.z())
        return Vec3(*(dot(r, q) for r in self.rows))

    def points(self, p):
        """point() of every row of a (K, 3) numpy array, in the same arithmetic (so
        the same floats, bit for bit)."""
        return self._rotate(p * self.scale.tolist(), self.translate.tolist())

    def normals(self, n):
        """normal() of every row of a (K, 3) numpy array, bit for bit."""
        return self._rotate(n / self.scale.tolist())

    def _rotate(self, q, shift=None):
        import numpy as np

        out = np.empty_like(q)
        for i, r in enumerate(self.rows):  # dot(r, q) (+ shift), term by term as dot() adds
            out[:, i] = q[:, 0] * r.x() + q[:, 1] * r.y() + q[:, 2] * r.z()
            if shift is not None:
                out[:, i] += shift[i]
        return out


def _rotation(axis: int, angle: float) -> list[list[float]]:
    c, s = math.cos(angle), math.sin(angle)
    i, j = [k for k in range(3) if k != axis]  # the plane rotated: y-z, z-x or x-y
    if axis == 1:
        i, j = j, i  # about y, z turns toward x
    m = [[1.0 if r == k else 0.0 for k in range(3)] for r in range(3)]
    m[i][i], m[i][j], m[j][i], m[j][j] = c, -s, s, c
    return m


def _matmul(a: list[list[float]], b: list[list[float]]) -> list[list[float]]:
    return [[sum(a[r][k] * b[k][c] for k in range(3)) for c in range(3)] for r in range(3)]


def _usable(n: Vec3) -> bool:
    length = n.length()
    return math.isfinite(length) and length > 0.0


class Mesh(Hittable):
    """A triangle mesh, placed by a transform: one object of a scene, its triangles
    kept as arrays and searched through a BVH of its own.

        mesh = rtpy.mesh_from_obj("teapot.obj", Lambertian(), Transform(scale=Vec3(0.5, 0.5, 0.5)))
        scene = Scene([mesh, ...])

    positions  (P, 3) vertex positions; normals: (Q, 3) vertex normals (may be empty)
    triangles  (T, 3, 2): per triangle, its three corners (position index, normal
               index or -1 for none), 0-based, as rtpy.io.obj.ObjMesh.triangles; a
               list of corner triples ((p, n or None), ...) is read too
    A triangle whose three corners have usable (finite, non-zero) normals is a
    SmoothTriangle, else a flat Triangle. Faces that are degenerate after the
    transform (collinear corners) are left out and counted in `skipped`.

    The mesh is built once: the transformed vertices (`vertices`), the faces kept
    (`faces`, (T, 3) position indices, and `face_normals`, their normal indices or -1
    on every corner of a flat one) and the tree over them (`tree`, rtpy.bvh.Tree),
    all numpy arrays, so a million triangles take about a hundred MB and travel to
    worker processes with the scene as they are. It answers as the list of its
    triangles would (mesh[k] is triangle k, a Triangle or SmoothTriangle made when a
    ray first tests it): the closest hit, ties to the triangle earliest in the file.
    An emitting mesh is a light only as its triangles: Scene([*mesh.triangles]).
    """

    def __init__(self, positions, normals, triangles, material, transform: Transform | None = None):
        import numpy as np

        transform = transform or Transform()
        self.material = checked_material(material)
        positions = np.asarray(positions, dtype=np.float64).reshape(-1, 3)
        normals = np.asarray(normals, dtype=np.float64).reshape(-1, 3)
        corners = _corners(triangles, len(positions), len(normals))
        self.vertices = points = transform.points(positions)
        _check_vertices(points)
        shading = transform.normals(normals)
        faces = corners[:, :, 0]
        kept, lo, hi = _boxes(points, faces)
        self.skipped = int(len(kept) - np.count_nonzero(kept))
        corner_normals = corners[:, :, 1]
        if self.skipped:
            faces, corner_normals = faces.compress(kept, axis=0), corner_normals.compress(kept, 0)
        self.faces = faces.astype(np.int32)
        x, y, z = shading[:, 0], shading[:, 1], shading[:, 2]
        length = np.sqrt(x * x + y * y + z * z)  # Vec3.length
        usable = np.append(np.isfinite(length) & (length > 0.0), False)  # [-1]: none
        self.normals = shading
        self.face_normals = corner_normals.astype(np.int32)
        # A face with a corner of no usable normal is flat (-1 on every corner).
        if self.face_normals.size and not (usable[:-1].all() and self.face_normals.min() >= 0):
            self.face_normals[~usable[corner_normals].all(axis=1)] = -1
        del corner_normals
        self.tree: Tree | None = None
        if len(lo):
            from ._bvh_build import build_tree

            self.tree = build_tree(lo, hi)
        self.__setstate__({})

    @classmethod
    def from_arrays(
        cls, material, vertices, normals, faces, face_normals, tree: Tree, skipped: int = 0
    ) -> Mesh:
        """The mesh of arrays a Mesh was built with (its attributes of those names),
        with its tree, as rtpy.io.mesh_cache reads them back: nothing is computed."""
        mesh = cls.__new__(cls)
        mesh.material, mesh.vertices, mesh.normals = material, vertices, normals
        mesh.faces, mesh.face_normals, mesh.tree, mesh.skipped = faces, face_normals, tree, skipped
        mesh.__setstate__(mesh.__dict__)
        return mesh

    def __len__(self) -> int:
        return len(self.faces)

    def __getitem__(self, k: int) -> Triangle:
        """Triangle k (made on first use, then kept)."""
        tri = self._triangles[k]
        if tri is None:
            # As Triangle(a, b, c, material) or SmoothTriangle(...) make it, but
            # without checking each point again: the constructor checked them all.
            a, b, c = (Vec3(*p) for p in self.vertices[self.faces[k]].tolist())
            ns = self.face_normals[k]
            smooth = ns[0] >= 0
            kind = SmoothTriangle if smooth else Triangle
            tri = kind.__new__(kind)
            tri._place(a, b, c, self.material)
            if smooth:
                tri._shade([Vec3(*n) for n in self.normals[ns].tolist()])
            self._triangles[k] = tri
        return tri

    @property
    def triangles(self) -> list[Triangle]:
        """Every triangle, as objects (for a small mesh: a million objects take GBs)."""
        return [self[k] for k in range(len(self))]

    def __getstate__(self) -> dict:
        # The triangles made as objects, and the search over them, are made again
        # where they are needed.
        made = ("_triangles", "_bvh", "_last")
        return {k: v for k, v in self.__dict__.items() if k not in made}

    def __setstate__(self, state: dict) -> None:
        self.__dict__.update(state)
        self._triangles = [None] * len(self.faces)
        self._bvh = None if self.tree is None else BVH.over_tree(self, self.tree)
        self._last: tuple = (None, 0.0, 0)  # hit_t's last hit: (ray, t, triangle)

    def triangle_boxes(self):
        """(lo, hi), (T, 3) each: every triangle's box as Triangle.bounding_box makes
        it (padded by BOX_PADDING of its magnitude, at least an ulp), grown by
        ROUNDING_MARGIN of the mesh's magnitude as the BVH grows a scene's boxes."""
        _, lo, hi = _boxes(self.vertices, self.faces)
        return lo, hi

    # --- Hittable -----------------------------------------------------------------
    def hit_t(self, ray: Ray, t_min: float, t_max: float) -> float | None:
        if self._bvh is None:
            return None
        found = self._bvh.closest_hit(ray, t_min, t_max)
        if found is None:
            return None
        self._last = (ray, found[1], found[0])
        return found[1]

    def hit_info(self, ray: Ray, t: float) -> HitInfo:
        """The HitInfo of the triangle hit at t: the one hit_t found last when it was
        this ray and this t (the scene asks right after), else found again by a
        search of the interval around t alone, which enters only the boxes around
        that point. Either way the triangle a search of the whole ray finds."""
        last_ray, last_t, k = self._last
        if last_ray is not ray or last_t != t:
            k, _ = self._bvh.closest_hit(
                ray, math.nextafter(t, -math.inf), math.nextafter(t, math.inf)
            )
        return self[k].hit_info(ray, t)

    def bounding_box(self) -> AABB | None:
        if self.tree is None:
            return None
        lo, hi = self.tree.lo[0].tolist(), self.tree.hi[0].tolist()
        return AABB(Vec3(*lo), Vec3(*hi))


def _boxes(points, faces):
    """(kept, lo, hi) of the triangles of corners points[faces] ((T, 3) indices):
    kept (T,), whether a triangle is not degenerate (twice its area, |(b - a) x
    (c - a)| in Triangle's arithmetic, at least MIN_AREA); lo and hi, the kept
    triangles' boxes as Mesh.triangle_boxes makes them, (T', 3) views of (3, T')
    columns."""
    import numpy as np

    count = len(faces)
    kept = np.empty(count, dtype=bool)
    lo, hi, margin = np.empty((3, count)), np.empty((3, count)), np.empty(count)
    largest = 0.0  # magnitude of the kept triangles
    # The corners as columns (3, T), where numpy is fastest, a block of triangles at a
    # time: the temporaries stay in the processor's cache and are made once.
    columns = np.ascontiguousarray(points.T)
    for s in range(0, count, BLOCK):
        e = min(s + BLOCK, count)
        a, b, c = (columns.take(faces[s:e, i], axis=1) for i in range(3))
        n = _cross(b - a, c - a)
        keep = kept[s:e]
        np.greater_equal(np.sqrt(n[0] * n[0] + n[1] * n[1] + n[2] * n[2]), MIN_AREA, out=keep)
        low, high = lo[:, s:e], hi[:, s:e]
        np.minimum(np.minimum(a, b, out=n), c, out=low)
        np.maximum(np.maximum(a, b, out=n), c, out=high)
        # max(|lo|, |hi|) is max(hi, -lo) as lo <= hi (up to the sign of a zero, which
        # the largest over x, y, z is only for a degenerate triangle at the origin)
        size = np.maximum(high, np.negative(low, out=n), out=n)
        magnitude = np.maximum(np.maximum(size[0], size[1]), size[2])
        np.maximum(BOX_PADDING * magnitude, np.spacing(magnitude), out=margin[s:e])
        if keep.any():
            largest = max(largest, float(magnitude.compress(keep).max()))
    if not kept.all():
        lo, hi, margin = lo.compress(kept, 1), hi.compress(kept, 1), margin.compress(kept)
    # The padding, and the tree's margin for rounding (rtpy/bvh.py)
    margin += ROUNDING_MARGIN * largest
    lo -= margin
    hi += margin
    return kept, lo.T, hi.T


def _cross(u, v):
    """cross() of the columns of two (3, K) arrays, in its arithmetic."""
    import numpy as np

    out = np.empty_like(u)
    out[0] = u[1] * v[2] - u[2] * v[1]
    out[1] = u[2] * v[0] - u[0] * v[2]
    out[2] = u[0] * v[1] - u[1] * v[0]
    return out


def _corners(triangles, n_positions: int, n_normals: int):
    """The (T, 3, 2) int64 array of the triangles' corners, checked against the
    counts of positions and normals (ValueError naming `triangles`)."""
    import numpy as np

    if not isinstance(triangles, np.ndarray):
        triangles = [[(p, -1 if n is None else n) for p, n in tri] for tri in triangles]
    corners = np.asarray(triangles, dtype=np.int64).reshape(-1, 3, 2)
    p, n = corners[:, :, 0], corners[:, :, 1]
    if p.size and (p.min() < 0 or p.max() >= n_positions):
        raise ValueError(f"triangles: a position index is outside 0 .. {n_positions - 1}")
    if n.size and (n.min() < -1 or n.max() >= n_normals):
        raise ValueError(f"triangles: a normal index is outside -1 .. {n_normals - 1}")
    return corners


def _check_vertices(points) -> None:
    """The vertices after the transform are points in range: else the error of the
    first that is not, naming it as `vertex N (after the transform)`."""
    import numpy as np

    bad = ~(np.abs(points) <= MAX_COORDINATE).all(axis=1)  # nan fails too
    if bad.any():
        k = int(np.flatnonzero(bad)[0])
        checked(f"vertex {k + 1} (after the transform)", point, points[k].tolist())
