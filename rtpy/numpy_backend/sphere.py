"""SphereSet: all spheres of a scene as arrays, the batched twin of rtpy/sphere.py.

Intersections use the scalar Sphere.hit_t's cancellation-free root formula,
operation for operation, so t is bit-identical to the scalar one. As area lights,
spheres seen from outside are sampled by the cone they subtend (uniform by solid
angle), from inside uniformly by area, as Sphere.sample_direction.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ..sampling import cone_pdf
from ..sphere import Sphere
from .arrays import at, axpy, dot, put_rows, scale
from .hittable import INF, PrimitiveSet, area_direction, area_direction_pdf
from .sampling import cone_direction, uniform_sphere
from .vec3 import rows_of, stack

# Brute-force spheres take rays in chunks of this many: the cheap test's (K, chunk)
# temporaries stay near the cache while the numpy calls stay few.
SPHERE_CHUNK = 16384


# Twin kept: Sphere.hit_t is the week-4 exercise, in Vec3 form with early misses.
def one_minus_cos_max(r2: np.ndarray, d2: np.ndarray) -> np.ndarray:
    """rtpy.sphere.one_minus_cos_max on arrays: sin^2 / (1 + cos) with sin^2 = r2 / d2."""
    sin2 = r2 / d2
    return sin2 / (1.0 + np.sqrt(1.0 - sin2))


def nearer_root(d2, r2, distance, cos_t, sin2_t) -> np.ndarray:
    """rtpy.sphere.nearer_root on arrays: (D^2 - r^2) / (D cos_t + sqrt(r^2 - D^2 sin^2_t))."""
    return (d2 - r2) / (distance * cos_t + np.sqrt(np.maximum(0.0, r2 - d2 * sin2_t)))


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


class SphereSet(PrimitiveSet):
    """Spheres: center (K, 3), radius (K,). Geometric normal outward."""

    one_index_lights = True

    def __init__(self, spheres: Sequence[Sphere]) -> None:
        self.objects = list(spheres)
        self.center = rows_of(s.center for s in spheres)
        self.radius = np.array([float(s.radius) for s in spheres], dtype=np.float64)
        self.r2 = self.radius * self.radius
        self.center_columns = [self.center[:, c, None].copy() for c in range(3)]  # (K, 1)
        self.build_bvh()

    def bounding_boxes(self):
        r = self.radius[:, None]
        return self.center - r, self.center + r

    def hit_t(self, o, d, k, t_min, t_max):
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

    def closest_hit(self, o, d, t_min, t_max, any_hit=False, ignore=None):
        """As PrimitiveSet.closest_hit. Without a BVH, rays in chunks of SPHERE_CHUNK: a
        cheaper test than hit_t's (below) rejects, for every sphere and ray at once in
        (K, chunk) arrays (sphere by row, so numpy's inner loop runs over the rays),
        the pairs that surely miss; then sphere by sphere, hit_t's arithmetic, op for
        op, runs only for the rest, against the closest t found so far: t is
        bit-identical and ties keep the lower index (as argmin).

        The cheap test: hit_t misses where the sphere is behind an origin outside it
        (h < 0 and |oc|^2 > r^2), or where the line passes farther than r from the
        centre (f2 > r^2, f2 computed without cancellation). Here f2 is replaced by
        |oc|^2 - h^2 / a, which cancels but errs by only ~1e-15 |oc|^2, so rays are
        kept when it is at most r^2 + 1e-9 |oc|^2: a superset of hit_t's hits; the
        kept rays then get hit_t's exact test."""
        if self.bvh is not None:
            return super().closest_hit(o, d, t_min, t_max, any_hit, ignore)
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
                None if ignore is None else ignore[s:e],
            )
        return t_best, idx

    def _closest_chunk(self, o, d, t_min, t_best, idx, any_hit, ignore) -> None:
        """closest_hit for one chunk of rays, updating t_best and idx (views into
        closest_hit's results) in place. The chunk's components are copied to columns of
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
            if ignore is not None:
                cand &= ignore != k
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
        inv = 1.0 / np.sqrt(dot(nv, nv))
        n = scale(nv, inv)
        # Back onto the surface: removes the rounding of o + t d (as Sphere.hit_info).
        p = axpy(r, n, c)
        return p, n

    def surface_uv(self, k, point):
        c, r = self.center[k], self.radius[k]
        x = (point[:, 0] - c[:, 0]) / r
        y = (point[:, 1] - c[:, 1]) / r
        z = (point[:, 2] - c[:, 2]) / r
        theta = np.arccos(np.clip(-y, -1.0, 1.0))
        phi = np.arctan2(-z, x) + math.pi
        return phi / (2.0 * math.pi), theta / math.pi

    def surface_tangent(self, k, point):
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
        n = stack(*uniform_sphere(r1, r2))
        return self.center[k] + n * self.radius[k][:, None], n

    def cone(self, k, p) -> tuple[np.ndarray, np.ndarray]:
        """Sphere._cone: (outside (N,) bool, 1 - cos_max) of the cone the sphere
        subtends at p; only meaningful where outside."""
        dv = at(self.center, k) - p
        d2 = dot(dv, dv)
        r2 = at(self.r2, k)
        outside = ~(d2 <= r2 * 1.0000001)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):  # inside: unused
            return outside, one_minus_cos_max(r2, d2)

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
            axis = scale(axis, 1.0 / np.sqrt(dot(axis, axis)))
            dirs, _, _ = cone_direction(
                (axis[:, 0], axis[:, 1], axis[:, 2]),
                om,
                r1 if every else r1.take(o),
                r2 if every else r2.take(o),
            )
            if every:
                direction = np.stack(dirs, axis=1)
                pdf = cone_pdf(om)
                valid[:] = True
                return direction, pdf, valid
            put_rows(direction, o, np.stack(dirs, axis=1))
            pdf[o] = cone_pdf(om)
            valid[o] = True
        i = np.flatnonzero(~outside)
        if i.size:
            if isinstance(k, int):
                k = np.full(len(p), k)
            q, n = self.sample_point(k[i], r1[i], r2[i])
            direction[i], pdf[i], valid[i] = area_direction(p[i], q, n, self.area(k[i]))[:3]
        return direction, pdf, valid

    def sample_light(self, k, p, r1, r2):
        """PrimitiveSet.sample_light fused for one sphere (int k) that every point p
        sees from outside (a sphere lamp): the offset from p to the centre, computed
        once, serves the cone, its axis and the distance to the sphere. The direction
        and pdf are op for op those of cone() and sample_direction(). The distance is
        not traced (hit_t) but follows from the sampled angle theta to the axis: the
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
        omc = one_minus_cos_max(rr, d2)
        dist = np.sqrt(d2)
        inv = 1.0 / dist
        (dx, dy, dz), cos_t, sin2_t = cone_direction((ocx * inv, ocy * inv, ocz * inv), omc, r1, r2)
        pdf = cone_pdf(omc)
        # The distance to the sphere along the sampled direction (see above); inside
        # the cone, r^2 - D^2 sin^2 >= 0 but for rounding.
        t = nearer_root(d2, rr, dist, cos_t, sin2_t)
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
            pdf = cone_pdf(omc)
        if outside.all():
            return pdf
        return np.where(outside, pdf, area_direction_pdf(p, q, n, self.area(k)))
