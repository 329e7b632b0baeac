"""TriangleSet: triangles as arrays, the batched twin of rtpy/triangle.py (and of
rtpy/mesh.py's SmoothTriangle, whose vertex normals it interpolates); MeshSet: the
triangles of an rtpy.mesh.Mesh, read from its arrays and searched through its tree.

The all-pairs test is Moller-Trumbore in Plucker form, written as (N, 3) x (3, K)
matrix products; its t agrees with Triangle.hit_t's to ~1e-15.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..mesh import Mesh, SmoothTriangle
from ..triangle import PARALLEL_TOLERANCE, Triangle
from .arrays import at, axpy, dot, scale
from .bvh import BVH
from .hittable import INF, PlanarSet, area_direction_pdf
from .vec3 import rows_of


class TriangleSet(PlanarSet):
    """Triangles a, b, c; geometric normal normalize((b - a) x (c - a)).

    Moller-Trumbore in Plucker form: with e1 = b - a, e2 = c - a, m = o x d and
    N = e1 x e2, det = -(d . N), u det = e2 . m - d . (e2 x a),
    v det = -(e1 . m) - d . (a x e1), t det = o . N - a . N (all K-sided factors
    are precomputed; the ray-sided ones are (N, 3) x (3, K) products).

    The per-triangle rows the kernels read come through _edges, _plucker, _frame and
    _vertex_normals, which gather them from precomputed arrays here and compute them
    from a mesh's vertices in MeshSet.
    """

    def __init__(self, triangles: Sequence[Triangle], cluster: bool = True) -> None:
        super().__init__(triangles)
        self.a = rows_of(s.a for s in triangles)
        self.e1 = rows_of(s.e1 for s in triangles)
        self.e2 = rows_of(s.e2 for s in triangles)
        # Triangle's relative parallel test: det^2 <= parallel_det2 * |d|^2 is a miss.
        self.parallel_det2 = np.array([s._parallel_det2 for s in triangles], dtype=np.float64)
        self.N = np.cross(self.e1, self.e2)
        # Triangle.surface_uv's coordinate plane: axes (K, 2) and determinant (K,)
        self.plane_axes = np.array([s._plane_axes for s in triangles], dtype=np.int64)
        self.plane_det = np.array([s._plane_det for s in triangles], dtype=np.float64)
        self.e2xa = np.cross(self.e2, self.a)
        self.axe1 = np.cross(self.a, self.e1)
        self.aN = dot(self.a, self.N)
        # o-side: [N]; d-side: [N, e2 x a, a x e1]; m-side: [e2, e1]
        self.Mo = self.N.T.copy()
        self.Md = np.concatenate([self.N, self.e2xa, self.axe1], axis=0).T.copy()
        self.Mm = np.concatenate([self.e2, self.e1], axis=0).T.copy()
        # Vertex normals (K, 3, 3) of the SmoothTriangles, rows where `smooth` is True.
        self.smooth = np.array([isinstance(s, SmoothTriangle) for s in triangles], dtype=bool)
        self.vertex_normals = np.zeros((len(triangles), 3, 3))
        for i in np.flatnonzero(self.smooth):
            s = triangles[i]
            self.vertex_normals[i] = [[n.e0, n.e1, n.e2] for n in (s.na, s.nb, s.nc)]
        self.build_culling(cluster)

    # --- the rows of triangles k -------------------------------------------------
    def _edges(self, k):
        """(a, e1, e2) of triangles k."""
        return at(self.a, k), at(self.e1, k), at(self.e2, k)

    def _plucker(self, k):
        """(N, e1, e2, e2 x a, a x e1, a . N, parallel_det2) of triangles k."""
        return (
            at(self.N, k),
            at(self.e1, k),
            at(self.e2, k),
            at(self.e2xa, k),
            at(self.axe1, k),
            at(self.aN, k),
            at(self.parallel_det2, k),
        )

    def _frame(self, k):
        """(unit normal, plane axes (M, 2), plane determinant) of triangles k."""
        return self.normal.take(k, axis=0), self.plane_axes[k], self.plane_det[k]

    def _vertex_normals(self, k):
        """(smooth (M,) bool, unit vertex normals (M, 3, 3)) of triangles k."""
        return self.smooth[k], self.vertex_normals[k]

    def corners(self):
        return np.stack([self.a, self.a + self.e1, self.a + self.e2], 1)

    # Twin kept: Moller-Trumbore (the week-4 exercise) in Plucker form, whose ray-side
    # factors are one matrix product for all triangles.
    def _finish(self, det, parallel, u_num, v_num, t_num, t_min, t_max):
        # det = 0 or subnormal (parallel rays) makes u, v, t inf or NaN, and u + v
        # inf - inf; the parallel test below discards those rows.
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
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
        parallel = self.parallel_det2 * dot(d, d)[:, None]
        return self._finish(det, parallel, u_num, v_num, t_num, t_min, INF)

    def hit_t(self, o, d, k, t_min, t_max):
        m = np.cross(o, d)
        nn, e1, e2, e2xa, axe1, an, parallel_det2 = self._plucker(k)
        det = -dot(d, nn)
        u_num = dot(e2, m) - dot(d, e2xa)
        v_num = -dot(e1, m) - dot(d, axe1)
        t_num = dot(o, nn) - an
        parallel = parallel_det2 * dot(d, d)
        return self._finish(det, parallel, u_num, v_num, t_num, t_min, t_max)

    def surface_uv(self, k, point):
        # Triangle.surface_uv: Cramer's rule in each triangle's coordinate plane. Twin
        # kept: each row's plane axes are gathered (take_along_axis), not indexed.
        a, e1, e2 = self._edges(k)
        _, axes, det = self._frame(k)
        p = point - a
        i, j = axes[:, :1], axes[:, 1:]

        def pick(a, c):  # (N,) components c of the rows of a
            return np.take_along_axis(a, c, axis=1)[:, 0]

        u = (pick(p, i) * pick(e2, j) - pick(p, j) * pick(e2, i)) / det
        v = (pick(e1, i) * pick(p, j) - pick(e1, j) * pick(p, i)) / det
        return np.clip(u, 0.0, 1.0), np.clip(v, 0.0, 1.0)

    def shading_normal(self, k, point, geo):
        """SmoothTriangle.shading_normal at the hits `point` on triangles k (geometric
        normals geo): the interpolated vertex normal on geo's side; geo for flat ones."""
        # Twin kept: the weights of all rows in one einsum, where the scalar adds Vec3s.
        smooth, vertex_normals = self._vertex_normals(k)
        if not smooth.any():
            return geo
        u, v = self.surface_uv(k, point)
        w = np.stack([1.0 - u - v, u, v], axis=1)
        n = np.einsum("ij,ijk->ik", w, vertex_normals)
        length = np.sqrt(dot(n, n))
        smooth &= length > 0.0
        with np.errstate(divide="ignore", invalid="ignore"):
            n = n / length[:, None]
        n *= np.where(dot(n, geo) < 0.0, -1.0, 1.0)[:, None]
        return np.where(smooth[:, None], n, geo)

    def direction_pdf(self, k, p, q, n):
        # The density of sampling by area uses the geometric normal, not the shading one.
        return area_direction_pdf(p, q, self._frame(k)[0], self.area(k))

    def sample_point(self, k, r1, r2):
        s = np.sqrt(r1)  # rtpy.triangle.triangle_weights
        wb, wc = s * (1.0 - r2), s * r2
        a, e1, e2 = self._edges(k)
        p = a + wb[:, None] * e1 + wc[:, None] * e2
        return p, self._frame(k)[0]


class MeshSet(TriangleSet):
    """The triangles of a Mesh (local index k = the mesh's triangle k), read from the
    mesh's vertex and face arrays and searched through the tree the mesh was built
    with: nothing per triangle is computed or copied in the process that renders.
    The rows the kernels read are computed for the triangles asked for, with the
    scalar Triangle's arithmetic, so they equal TriangleSet's of the same triangles
    bit for bit."""

    def __init__(self, mesh: Mesh) -> None:
        self.mesh = mesh
        self.vertices, self.faces = mesh.vertices, mesh.faces
        self.face_normals, self.vertex_normal_rows = mesh.face_normals, mesh.normals
        self.bvh = BVH(tree=mesh.tree)
        self.clusters = None

    def __len__(self) -> int:
        return len(self.faces)

    @property
    def objects(self):
        return self.mesh  # mesh[k] is triangle k, as an object (made on first use)

    def _corners(self, k):
        f = self.faces.take(k, axis=0)
        return [self.vertices.take(f[..., i], axis=0) for i in range(3)]

    def _edges(self, k):
        a, b, c = self._corners(k)
        return a, b - a, c - a

    def _plucker(self, k):
        a, e1, e2 = self._edges(k)
        nn = np.cross(e1, e2)
        l1, l2 = np.sqrt(dot(e1, e1)), np.sqrt(dot(e2, e2))
        parallel_det2 = np.square(PARALLEL_TOLERANCE * l1 * l2)
        return nn, e1, e2, np.cross(e2, a), np.cross(a, e1), dot(a, nn), parallel_det2

    def _frame(self, k):
        _, e1, e2 = self._edges(k)
        n = np.cross(e1, e2)
        normal = scale(n, 1.0 / np.sqrt(dot(n, n)))  # Vec3 / length: times 1 / length
        drop = np.abs(n).argmax(axis=1)  # Triangle's coordinate plane (first largest)
        axes = np.stack([(drop + 1) % 3, (drop + 2) % 3], axis=1)
        return normal, axes, np.take_along_axis(n, drop[:, None], axis=1)[:, 0]

    def _vertex_normals(self, k):
        idx = self.face_normals.take(k, axis=0)
        smooth = idx[:, 0] >= 0
        rows = self.vertex_normal_rows
        if not smooth.any() or not len(rows):
            return smooth, np.zeros((len(idx), 3, 3))
        n = rows.take(np.maximum(idx, 0), axis=0)  # (M, 3, 3), as written after the transform
        length = np.sqrt(dot(n, n))
        with np.errstate(divide="ignore", invalid="ignore"):
            n = n * (1.0 / length)[..., None]  # unit_vector: times 1 / length
        return smooth, n

    def corners(self):
        return np.stack(self._corners(np.arange(len(self))), axis=1)

    def bounding_boxes(self):
        return self.mesh.triangle_boxes()

    def area(self, k):
        _, e1, e2 = self._edges(k)
        n = np.cross(e1, e2)
        return 0.5 * np.sqrt(dot(n, n))

    def geometric(self, k, o, d, t):
        return axpy(t, d, o), self._frame(k)[0]

    def surface_tangent(self, k, point):
        _, e1, _ = self._edges(k)
        return scale(e1, 1.0 / np.sqrt(dot(e1, e1))), np.ones(len(k), dtype=bool)
