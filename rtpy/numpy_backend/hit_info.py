"""HitBatch: N surface hits as arrays, the batched twin of the scalar HitInfo."""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from ..hit_info import HitInfo
from ..vec3 import Vec3
from .arrays import rows

if TYPE_CHECKING:
    from ..materials.material import Material


def unused(*shape: int) -> np.ndarray:
    """Zeros of the given shape for a field nothing reads (a HitBatch's (u, v) or
    tangent when the scene does not need them): a read-only broadcast, not allocated,
    and not copied by HitBatch.take. (np.broadcast_to would do, but costs a few times
    more than this direct construction, and HitBatches are made very often.)"""
    return np.ndarray(shape, np.float64, buffer=_ZERO, strides=(0,) * len(shape))


_ZERO = bytes(8)  # one float64 0.0, read-only


def _rows(a: np.ndarray, k: np.ndarray) -> np.ndarray:
    if a.strides[0] == 0:  # unused()
        return unused(len(k), *a.shape[1:])
    return rows(a, k)


@dataclass
class HitBatch:
    """N surface hits as float64 arrays, with the conventions of the scalar HitInfo.

    point       (N, 3) world positions
    normal      (N, 3) unit normals facing the arriving ray: dot(normal, wo) >= 0
    wo          (N, 3) unit directions toward the viewer, -(arriving ray's direction)
    t           (N,) ray parameters of the hits
    front_face  (N,) bool: the ray hit the side the geometric normal points to
    u, v        (N,) surface coordinates
    tangent     (N, 3) unit vectors in the surface along increasing u (what the scalar
                hit.tangent gives: the x axis of the shading frame)

    (u, v) and tangent are unused() zeros when nothing in the scene reads them.
    """

    point: np.ndarray
    normal: np.ndarray
    wo: np.ndarray
    t: np.ndarray
    front_face: np.ndarray
    u: np.ndarray
    v: np.ndarray
    tangent: np.ndarray

    def __len__(self) -> int:
        return len(self.t)

    def take(self, mask_or_index: np.ndarray) -> HitBatch:
        """The hits selected by a boolean mask or an integer index array. Each field is
        gathered when it is first read (a material kernel reads only some of them);
        the fields of a HitBatch are never modified in place, so this is the same."""
        k = mask_or_index
        if k.dtype == np.bool_:
            k = np.flatnonzero(k)
        return _HitRows(self, k)

    def hit_info(self, i: int, material: Material | None = None) -> HitInfo:
        """Hit i as a scalar HitInfo (for scalar fallbacks and tests); its tangent is
        this batch's tangent, its (u, v) this batch's."""
        p, n, s = self.point[i], self.normal[i], self.tangent[i]
        hit = HitInfo(
            Vec3(float(p[0]), float(p[1]), float(p[2])),
            Vec3(float(n[0]), float(n[1]), float(n[2])),
            float(self.t[i]),
            bool(self.front_face[i]),
            material,
            None,
            float(self.u[i]),
            float(self.v[i]),
        )
        hit.tangent = Vec3(float(s[0]), float(s[1]), float(s[2]))
        return hit


_FIELDS = frozenset(("point", "normal", "wo", "t", "front_face", "u", "v", "tangent"))


class _HitRows(HitBatch):
    """HitBatch.take's result: rows k of the parent's fields, each gathered on first
    read and then kept as an ordinary attribute."""

    def __init__(self, parent: HitBatch, k: np.ndarray) -> None:  # no dataclass fields yet
        self._parent = parent
        self._k = k

    def __len__(self) -> int:
        return len(self._k)

    def take(self, mask_or_index: np.ndarray) -> HitBatch:
        """Rows of rows: the parent's rows, gathered once when a field is read (not
        first into this batch, then again)."""
        k = mask_or_index
        if k.dtype == np.bool_:
            k = np.flatnonzero(k)
        return _HitRows(self._parent, self._k.take(k))

    def __getattr__(self, name: str) -> np.ndarray:
        if name not in _FIELDS:
            raise AttributeError(name)
        value = _rows(getattr(self._parent, name), self._k)
        setattr(self, name, value)
        return value
