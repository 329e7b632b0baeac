"""QuadSet: all quads of a scene as arrays, the batched twin of rtpy/quad.py.

The all-pairs test is written as (N, 4) x (4, K) matrix products, an algebraically
equal form of Quad.hit_t whose t agrees with the scalar one to ~1e-15.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..quad import Quad
from .arrays import at, axpy, dot
from .hittable import INF, PlanarSet
from .ray import ray_columns
from .vec3 import rows_of

# Quads accept hits this little outside their edges (in units of the edge length):
# rounding differs from the scalar formula's, and without the margin a ray exactly
# along the shared edge of two quads (a corner of a closed box) could slip between.
EDGE_A = 1e-9
EDGE = 1.0 + 2.0 * EDGE_A  # the same margin for |2a - 1| <= 1
_MISS = np.array([np.inf, -np.inf])  # by ok: fmax(t, _MISS[ok]) is t where ok, else inf


class QuadSet(PlanarSet):
    """Quads q + a u + b v, a, b in [0, 1]; geometric normal normalize(u x v).

    With w = n / (n . n) for n = u x v, the scalar coordinates of a point p are
    a = w . ((p - q) x v) = (p - q) . (v x w) and b = w . (u x (p - q)) = (p - q) . (w x u),
    so for p = o + t d: a = o . A + t (d . A) - q . A with A = v x w (B = w x u likewise).
    """

    def __init__(self, quads: Sequence[Quad], cluster: bool = True) -> None:
        super().__init__(quads)
        self.q = rows_of(s.q for s in quads)
        self.u = rows_of(s.u for s in quads)
        self.v = rows_of(s.v for s in quads)
        self.w = rows_of(s.w for s in quads)
        self.plane_d = np.array([float(s.d) for s in quads], dtype=np.float64)
        self.A = np.cross(self.v, self.w)
        self.B = np.cross(self.w, self.u)
        self.qA = dot(self.q, self.A)
        self.qB = dot(self.q, self.B)
        # Products for pair_t: (K, 4) for homogeneous origins, (K, 3) for directions.
        self.Mo_n = np.hstack([-self.normal, self.plane_d[:, None]])
        self.Mo_a = np.hstack([2.0 * self.A, (-2.0 * self.qA - 1.0)[:, None]])
        self.Mo_b = np.hstack([2.0 * self.B, (-2.0 * self.qB - 1.0)[:, None]])
        self.Md_a = 2.0 * self.A
        self.Md_b = 2.0 * self.B
        self.build_culling(cluster)

    def corners(self):
        return np.stack([self.q, self.q + self.u, self.q + self.v, self.q + self.u + self.v], 1)

    def all_t(self, o, d, t_min, t_max=None):
        t = self.pair_t(o, d, t_min, t_max)
        return np.full((len(o), len(self)), INF) if t is None else t.T

    def pair_t(self, o, d, t_min, t_max=None, columns=None):
        """As PrimitiveSet.pair_t. With t_max (N,) (occlusion), the edges are tested
        only for the quads whose plane some ray crosses in (t_min, t_max), and None
        says that there are none: a shadow ray inside a room crosses none of the
        walls' planes."""
        # Homogeneous o: one product gives d - o.n and 2 (o.A - q.A) - 1 (and for B),
        # so a' = 2a - 1 and b' = 2b - 1 need one multiply-add each and the test
        # 0 <= a, b <= 1 becomes max(|a'|, |b'|) <= 1.
        oh, d = ray_columns(o, d) if columns is None else columns
        # A ray (almost) parallel to a plane meets it at t = inf or NaN (over a
        # subnormal denominator): a miss, as every comparison below finds.
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            t = (self.Mo_n @ oh) / (self.normal @ d)
            if t_max is None:
                return self._inside(oh, d, t, t_min, slice(None))
            crossed = (t > t_min) & (t < t_max)
            quads = np.flatnonzero(crossed.any(axis=1))
            if quads.size == 0:
                return None
            if quads.size == len(self):
                return self._inside(oh, d, t, t_min, slice(None))
            out = np.full(t.shape, INF)
            out[quads] = self._inside(oh, d, t[quads], t_min, quads)
            return out

    def _inside(self, oh, d, t, t_min, quads):
        """t where the hits at t on the quads `quads` lie inside them (else inf)."""
        a = self.Mo_a[quads] @ oh
        a += t * (self.Md_a[quads] @ d)
        b = self.Mo_b[quads] @ oh
        b += t * (self.Md_b[quads] @ d)
        np.abs(a, out=a)
        np.abs(b, out=b)
        np.maximum(a, b, out=a)
        ok = a <= EDGE
        ok &= t > t_min
        # np.where(ok, t, inf), which numpy runs several times slower
        return np.fmax(t, _MISS.take(ok.view(np.uint8)))

    # Twin kept: Quad.hit_t is the week-4 exercise; here (a, b) by the A, B products.
    def hit_t(self, o, d, k, t_min, t_max):
        n = self.normal[k]
        A, B = self.A[k], self.B[k]
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # as in all_t
            t = (self.plane_d[k] - dot(n, o)) / dot(n, d)
            a = dot(o, A) - self.qA[k] + t * dot(d, A)
            b = dot(o, B) - self.qB[k] + t * dot(d, B)
        ok = (t > t_min) & (t < t_max) & (a >= -EDGE_A) & (a <= 1.0 + EDGE_A)
        ok &= (b >= -EDGE_A) & (b <= 1.0 + EDGE_A)
        return np.where(ok, t, INF)

    def surface_uv(self, k, point):
        # Quad._coords, then clamped to [0, 1]. Twin kept: _coords is the week-4
        # exercise in Vec3 form (cross, dot); here the same products column by column.
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
