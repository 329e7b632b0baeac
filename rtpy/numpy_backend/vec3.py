"""n vectors as three (n,) columns: the batched rtpy.vec3.

Where the scalar code computes with Vec3 operations (a material's directions, a
frame's axes), a batch of n vectors is a tuple (x, y, z) of (n,) arrays, and `dot`,
`cross`, `reflect`, `halfvector`, ... below are the scalar functions on such tuples.
Where vectors are stored and gathered (HitBatch, rays), they are (n, 3) arrays;
`components` and `stack` convert, and `row`, `rows_of` and `to_vec3` convert from and
to the scalar Vec3. Every function uses the scalar code's operations in
the scalar code's order, so the results agree to the last bit.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from ..vec3 import Vec3
from .arrays import Rows

Columns = tuple[np.ndarray, np.ndarray, np.ndarray]


def components(a: np.ndarray) -> Columns:
    """The columns of an (n, 3) array."""
    return a[:, 0], a[:, 1], a[:, 2]


def stack(x: np.ndarray, y: np.ndarray, z: np.ndarray) -> np.ndarray:
    """(n, 3) array from three (n,) columns."""
    return np.stack((x, y, z), axis=1)


def take(v: Columns, rows: Rows) -> Columns:
    """The rows `rows` of every column."""
    return v[0][rows], v[1][rows], v[2][rows]


def dot(a: Columns, b: Columns) -> np.ndarray:
    return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]


def negative(v: Columns) -> Columns:
    """-v (rtpy.vec3.Vec3.__neg__)."""
    return -v[0], -v[1], -v[2]


def cross(a: Columns, b: Columns) -> Columns:
    """rtpy.vec3.cross: a x b."""
    (a0, a1, a2), (b0, b1, b2) = a, b
    return a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0


def unit_vector(v: Columns) -> Columns:
    """rtpy.vec3.unit_vector: v / |v|, as Vec3 divides (one reciprocal, three products)."""
    k = 1.0 / np.sqrt(dot(v, v))
    return v[0] * k, v[1] * k, v[2] * k


def halfvector(view: Columns, light: Columns) -> Columns:
    """rtpy.vec3.halfvector: the unit half vector (view + light) / |view + light|."""
    return unit_vector((view[0] + light[0], view[1] + light[1], view[2] + light[2]))


def reflect(v: Columns, n: Columns) -> Columns:
    """rtpy.vec3.reflect: v mirrored about the plane with unit normal n."""
    k = 2.0 * dot(v, n)
    return v[0] - k * n[0], v[1] - k * n[1], v[2] - k * n[2]


def refract(uv: Columns, n: Columns, etai_over_etat: np.ndarray) -> Columns:
    """rtpy.vec3.refract: Snell refraction of the unit vectors uv (pointing toward the
    surface) through the unit normals n facing them. The caller checks for total
    internal reflection."""
    cos_theta = np.minimum(-dot(uv, n), 1.0)
    perp = tuple((uv[c] + n[c] * cos_theta) * etai_over_etat for c in range(3))
    s = -np.sqrt(np.abs(1.0 - dot(perp, perp)))
    return perp[0] + n[0] * s, perp[1] + n[1] * s, perp[2] + n[2] * s


def row(v: Vec3) -> np.ndarray:
    """A Vec3 as a (3,) float64 array."""
    return np.array([float(v.e0), float(v.e1), float(v.e2)])


def rows_of(vectors: Iterable[Vec3]) -> np.ndarray:
    """(K, 3) float64 array of K Vec3s (K may be 0)."""
    return np.array([[float(v.e0), float(v.e1), float(v.e2)] for v in vectors]).reshape(-1, 3)


def to_vec3(a: np.ndarray) -> Vec3:
    """A (3,) row as a Vec3 of Python floats (for the scalar code)."""
    return Vec3(float(a[0]), float(a[1]), float(a[2]))
