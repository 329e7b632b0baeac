"""TriangleSet: all triangles of a scene as arrays, the batched twin of rtpy/triangle.py
(and of rtpy/mesh.py's SmoothTriangle, whose vertex normals it interpolates).

The all-pairs test is Moller-Trumbore in Plucker form, written as (N, 3) x (3, K)
matrix products; its t agrees with Triangle.hit_t's to ~1e-15.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..mesh import SmoothTriangle
from ..triangle import Triangle
from .arrays import at, dot
from .hittable import INF, PlanarSet, area_direction_pdf
from .vec3 import rows_of


class TriangleSet(PlanarSet):
    """Triangles a, b, c; geometric normal normalize((b - a) x (c - a)).

    Moller-Trumbore in Plucker form: with e1 = b - a, e2 = c - a, m = o x d and
    N = e1 x e2, det = -(d . N), u det = e2 . m - d . (e2 x a),
    v det = -(e1 . m) - d . (a x e1), t det = o . N - a . N (all K-sided factors
    are precomputed; the ray-sided ones are (N, 3) x (3, K) products).
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

    def corners(self):
        return np.stack([self.a, self.a + self.e1, self.a + self.e2], 1)

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
        nn = at(self.N, k)
        det = -dot(d, nn)
        u_num = dot(at(self.e2, k), m) - dot(d, at(self.e2xa, k))
        v_num = -dot(at(self.e1, k), m) - dot(d, at(self.axe1, k))
        t_num = dot(o, nn) - at(self.aN, k)
        parallel = at(self.parallel_det2, k) * dot(d, d)
        return self._finish(det, parallel, u_num, v_num, t_num, t_min, t_max)

    def surface_uv(self, k, point):
        # Triangle.surface_uv: Cramer's rule in each triangle's coordinate plane.
        p = point - self.a[k]
        axes = self.plane_axes[k]
        i, j = axes[:, :1], axes[:, 1:]

        def pick(a, c):  # (N,) components c of the rows of a
            return np.take_along_axis(a, c, axis=1)[:, 0]

        e1, e2, det = self.e1[k], self.e2[k], self.plane_det[k]
        u = (pick(p, i) * pick(e2, j) - pick(p, j) * pick(e2, i)) / det
        v = (pick(e1, i) * pick(p, j) - pick(e1, j) * pick(p, i)) / det
        return np.clip(u, 0.0, 1.0), np.clip(v, 0.0, 1.0)

    def shading_normal(self, k, point, geo):
        """SmoothTriangle.shading_normal at the hits `point` on triangles k (geometric
        normals geo): the interpolated vertex normal on geo's side; geo for flat ones."""
        smooth = self.smooth[k]
        if not smooth.any():
            return geo
        u, v = self.surface_uv(k, point)
        w = np.stack([1.0 - u - v, u, v], axis=1)
        n = np.einsum("ij,ijk->ik", w, self.vertex_normals[k])
        length = np.sqrt(dot(n, n))
        smooth &= length > 0.0
        with np.errstate(divide="ignore", invalid="ignore"):
            n = n / length[:, None]
        n *= np.where(dot(n, geo) < 0.0, -1.0, 1.0)[:, None]
        return np.where(smooth[:, None], n, geo)

    def direction_pdf(self, k, p, q, n):
        # The density of sampling by area uses the geometric normal, not the shading one.
        return area_direction_pdf(p, q, self.normal[k], self.area(k))

    def sample_point(self, k, r1, r2):
        s = np.sqrt(r1)
        wb, wc = s * (1.0 - r2), s * r2
        p = self.a[k] + wb[:, None] * self.e1[k] + wc[:, None] * self.e2[k]
        return p, self.normal[k]
