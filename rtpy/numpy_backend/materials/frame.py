"""Batched vector helpers shared by the material kernels.

A local direction is a tuple (x, y, z) of (n,) arrays, so kernels read like the scalar
code, which writes local directions as tuples of floats (`wo[0] * wi[0] + ...`).
World vectors are (n, 3) arrays, as in HitBatch. Every formula is written with the
scalar code's operations in the scalar code's order, so the results agree to the
last bit wherever numpy's elementary functions agree with the C library's; azimuths
are the exception: cos and sin of 2 pi u come from rtpy/numpy_backend/trig.py, which
agrees with the C library to ~1e-16 (and is closer to the exact values).
"""

from __future__ import annotations

import numpy as np

from ..trig import cos_sin_2pi

Local = tuple[np.ndarray, np.ndarray, np.ndarray]


def components(a: np.ndarray) -> Local:
    """The columns of an (n, 3) array."""
    return a[:, 0], a[:, 1], a[:, 2]


def stack(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
    """(n, 3) array from three (n,) columns."""
    return np.stack((x, y, z), axis=1)


Rows = np.ndarray | slice  # an index array, or slice(None) for all rows


def select(mask: np.ndarray) -> Rows:
    """The rows where mask is True; slice(None) when that is all of them, so that
    indexing with the result costs nothing in the common case."""
    return slice(None) if mask.all() else np.flatnonzero(mask)


def compose(outer: Rows, inner: Rows) -> Rows:
    """The rows `inner` of the rows `outer`."""
    if isinstance(inner, slice):
        return outer
    if isinstance(outer, slice):
        return inner
    return outer[inner]


def take(v: Local, rows: Rows) -> Local:
    return v[0][rows], v[1][rows], v[2][rows]


def dot(a: Local, b: Local) -> np.ndarray:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def reflect(v: Local, n: Local) -> Local:
    """rtpy.vec3.reflect: v mirrored about the plane with unit normal n."""
    k = 2.0 * dot(v, n)
    return v[0] - k * n[0], v[1] - k * n[1], v[2] - k * n[2]


def duff_basis(w: Local) -> tuple[Local, Local]:
    """(u, v) of rtpy.onb.ONB(w): Duff et al. 2017's branchless frame around unit w."""
    w0, w1, w2 = w
    sign = np.copysign(1.0, w2)
    a = -1.0 / (sign + w2)
    b = w0 * w1 * a
    u = (1.0 + sign * w0 * w0 * a, sign * b, -sign * w0)
    v = (b, sign + w1 * w1 * a, -w1)
    return u, v


def local_to_world(w: Local, x: np.ndarray, y: np.ndarray, z: np.ndarray) -> Local:
    """rtpy.onb.local_to_world: x u + y v + z w in the frame ONB(w) builds."""
    w0, w1, w2 = w
    sign = np.copysign(1.0, w2)
    a = -1.0 / (sign + w2)
    b = w0 * w1 * a
    return (
        x * (1.0 + sign * w0 * w0 * a) + y * b + z * w0,
        x * sign * b + y * (sign + w1 * w1 * a) + z * w1,
        -x * sign * w0 - y * w1 + z * w2,
    )


def cosine_direction(r1: np.ndarray, r2: np.ndarray) -> Local:
    """rtpy.sampling.random_cosine_direction from its two uniform numbers."""
    cos_phi, sin_phi = cos_sin_2pi(r1)
    s = np.sqrt(r2)
    return s * cos_phi, s * sin_phi, np.sqrt(np.maximum(0.0, 1.0 - r2))


def uniform_sphere(r1: np.ndarray, r2: np.ndarray) -> Local:
    """rtpy.sampling.uniform_sphere: uniform on the unit sphere."""
    z = 1.0 - 2.0 * r1
    s = np.sqrt(np.maximum(0.0, 1.0 - z * z))
    cos_phi, sin_phi = cos_sin_2pi(r2)
    return s * cos_phi, s * sin_phi, z


class Frame:
    """Batched rtpy.onb.ONB.from_normal_tangent: w = normal, u = the tangent made
    perpendicular to it (Gram-Schmidt), v = w x u; ONB(normal) where the tangent lies
    along the normal (length of its perpendicular part < 1e-9)."""

    __slots__ = ("u", "v", "w")

    def __init__(self, u: Local, v: Local, w: Local) -> None:
        self.u, self.v, self.w = u, v, w

    @classmethod
    def from_normal_tangent(cls, normal: np.ndarray, tangent: np.ndarray) -> Frame:
        w = components(normal)
        t = components(tangent)
        k = dot(t, w)
        ux, uy, uz = t[0] - k * w[0], t[1] - k * w[1], t[2] - k * w[2]
        length = np.sqrt(ux * ux + uy * uy + uz * uz)
        degenerate = length < 1e-9
        if degenerate.any():
            length = np.where(degenerate, 1.0, length)
        u = (ux / length, uy / length, uz / length)
        v = (
            w[1] * u[2] - w[2] * u[1],
            w[2] * u[0] - w[0] * u[2],
            w[0] * u[1] - w[1] * u[0],
        )
        if degenerate.any():
            du, dv = duff_basis(w)
            u = tuple(np.where(degenerate, a, b) for a, b in zip(du, u, strict=True))
            v = tuple(np.where(degenerate, a, b) for a, b in zip(dv, v, strict=True))
        return cls(u, v, w)

    def take(self, rows: Rows) -> Frame:
        return Frame(take(self.u, rows), take(self.v, rows), take(self.w, rows))

    def to_local(self, d: np.ndarray) -> Local:
        """Coordinates of the world vectors d (n, 3) in the frame (z along w)."""
        d = components(d)
        return dot(d, self.u), dot(d, self.v), dot(d, self.w)

    def to_world(self, x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
        u, v, w = self.u, self.v, self.w
        return stack(
            x * u[0] + y * v[0] + z * w[0],
            x * u[1] + y * v[1] + z * w[1],
            x * u[2] + y * v[2] + z * w[2],
        )
