"""Batched textures, the twin of rtpy/texture.py: the colours of many textures at many
hits in a few numpy calls.

A TextureTable holds the textures of a scene (texture id = index into the list) as
structure-of-arrays parameters per texture class, so looking up N hits costs the
same few numpy calls whether they use one texture or five hundred:

- SolidColor: a gather from an (T, 3) colour array, nothing else;
- CheckerTexture: the 3-D cell parity of the scalar class;
- ImageTexture: every image flattened into one atlas of texels, looked up by the
  scalar class's nearest-pixel rule at a per-texture offset;
- any other Texture (a subclass included: dispatch is by exact type) is called
  per hit through its scalar value(), so a student's texture still works.
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..texture import CheckerTexture, ImageTexture, SolidColor, Texture
from .hit_info import HitBatch

SOLID, CHECKER, IMAGE, SCALAR = 0, 1, 2, 3


def clamp01(x: np.ndarray) -> np.ndarray:
    """min(1, max(0, x)) with Python's semantics (NaN becomes 0, as in the scalar code)."""
    x = np.where(x > 0.0, x, 0.0)
    return np.where(x < 1.0, x, 1.0)


def checker_is_even(point: np.ndarray, inv_scale: np.ndarray) -> np.ndarray:
    """(N,) bool: floor(px k) + floor(py k) + floor(pz k) is even, k = 1 / scale (N,)."""
    cells = np.floor(point * inv_scale[:, None]).astype(np.int64).sum(axis=1)
    return cells % 2 == 0


def nearest_texel(
    u: np.ndarray, v: np.ndarray, width: np.ndarray, height: np.ndarray
) -> tuple[np.ndarray, np.ndarray]:
    """Column i and row j (row 0 at the top) of the texel at (u, v), as ImageTexture.value:
    u, v clamped to [0, 1], v = 0 at the bottom row, the edge u = 1 in the last column."""
    i = np.minimum((clamp01(u) * width).astype(np.int64), width - 1)
    j = np.minimum(((1.0 - clamp01(v)) * height).astype(np.int64), height - 1)
    return i, j


class TextureTable:
    """Batched twins of a list of textures; texture id = index into `textures`."""

    def __init__(self, textures: Sequence[Texture]) -> None:
        self.textures = list(textures)
        n = len(self.textures)
        self.kind = np.full(n, SCALAR, dtype=np.int8)
        self.color = np.zeros((n, 3))  # SolidColor's colour
        self.inv_scale = np.ones(n)  # CheckerTexture's 1 / scale, even and odd
        self.even = np.zeros((n, 3))
        self.odd = np.zeros((n, 3))
        self.width = np.ones(n, dtype=np.int64)  # ImageTexture: size and atlas offset
        self.height = np.ones(n, dtype=np.int64)
        self.offset = np.zeros(n, dtype=np.int64)
        images: list[np.ndarray] = []
        placed: dict[int, int] = {}  # id(pixels) -> offset: a shared image is stored once
        size = 0
        for k, tex in enumerate(self.textures):
            cls = type(tex)
            if cls is SolidColor:
                self.kind[k] = SOLID
                self.color[k] = tuple(tex.color)
            elif cls is CheckerTexture:
                self.kind[k] = CHECKER
                self.inv_scale[k] = tex.inv_scale
                self.even[k] = tuple(tex.even)
                self.odd[k] = tuple(tex.odd)
            elif cls is ImageTexture:
                self.kind[k] = IMAGE
                self.width[k], self.height[k] = tex.width, tex.height
                if id(tex.pixels) not in placed:
                    placed[id(tex.pixels)] = size
                    images.append(np.asarray(tex.pixels, dtype=np.float64).reshape(-1, 3))
                    size += tex.width * tex.height
                self.offset[k] = placed[id(tex.pixels)]
        self.atlas = np.concatenate(images) if images else np.zeros((0, 3))
        # (not np.unique: its first call imports a module, which every worker would pay)
        self.kinds_present = frozenset(self.kind.tolist())
        # Only image textures and textures without a batched twin read (u, v).
        self.reads_uv = bool(self.kinds_present & {IMAGE, SCALAR})

    def value(
        self, ids: np.ndarray, hits: HitBatch, rows: np.ndarray | slice = slice(None)
    ) -> np.ndarray:
        """(n, 3) linear colours of textures `ids` (n,) at the hits `rows` of `hits`
        (all of them by default), as Texture.value."""
        ids = np.asarray(ids, dtype=np.intp)
        if self.kinds_present <= {SOLID}:
            return self.color.take(ids, axis=0)
        kind = self.kind[ids]
        out = self.color.take(ids, axis=0)  # right for the solid ones; the others are overwritten
        rows = np.arange(len(hits))[rows]  # hit row of every id
        if CHECKER in self.kinds_present:
            sel = np.flatnonzero(kind == CHECKER)
            if len(sel):
                t = ids[sel]
                even = checker_is_even(hits.point[rows[sel]], self.inv_scale[t])
                out[sel] = np.where(even[:, None], self.even[t], self.odd[t])
        if IMAGE in self.kinds_present:
            sel = np.flatnonzero(kind == IMAGE)
            if len(sel):
                t, r = ids[sel], rows[sel]
                w = self.width[t]
                i, j = nearest_texel(hits.u[r], hits.v[r], w, self.height[t])
                out[sel] = self.atlas[self.offset[t] + j * w + i]
        if SCALAR in self.kinds_present:
            for s in np.flatnonzero(kind == SCALAR):
                out[s] = tuple(self.textures[ids[s]].value(hits.hit_info(rows[s])))
        return out
