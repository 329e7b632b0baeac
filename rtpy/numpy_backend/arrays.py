"""Row operations on (N,) and (N, 3) float64 arrays, spelled the way numpy runs fast.

The backend stores vectors as C-contiguous (N, 3) arrays, one row per ray or hit.
For such arrays several of numpy's natural spellings run their innermost loop over
the three components and pay a per-row overhead, several times the cost of an
equivalent spelling:

- gathering rows: a.take(idx, axis=0) and a.compress(mask, axis=0), not a[idx] or
  a[mask];
- scattering rows: np.put on a view of each row as one 24-byte item, not out[idx] = x;
- scaling rows, dot products, reductions over the three components: three column
  operations, not a * s[:, None], a.sum(axis=1) or a.max(axis=1).

The helpers below give the fast spelling with the meaning of the natural one. Each
takes index arrays (int) or boolean masks where it says so; results are new
C-contiguous arrays unless `out` is given.
"""

from __future__ import annotations

import numpy as np

_ROW = np.dtype((np.void, 24))  # one (3,) float64 row as a single item

Rows = np.ndarray | slice  # an index array, or slice(None) for all rows


def rows(a: np.ndarray, index: np.ndarray) -> np.ndarray:
    """a[index] for an int index array or a boolean mask over a's first axis."""
    if index.dtype == np.bool_:
        return a.compress(index, axis=0)
    return a.take(index, axis=0)


def at(table: np.ndarray, k: np.ndarray | int) -> np.ndarray:
    """table.take(k, axis=0): rows of a table per index; for one int k, that row
    alone (a scalar or a (3,) row, which broadcasts against the (N,) columns)."""
    return table[k] if isinstance(k, int) else table.take(k, axis=0)


def true(n: int) -> np.ndarray:
    """(n,) bool, all True."""
    return np.ones(n, dtype=bool)


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


def _as_items(a: np.ndarray) -> np.ndarray | None:
    """a (N, 3) float64 C-contiguous viewed as (N,) 24-byte items, else None."""
    if a.ndim == 2 and a.shape[1] == 3 and a.dtype == np.float64 and a.flags.c_contiguous:
        return a.view(_ROW).reshape(-1)
    return None


def put_rows(out: np.ndarray, index: np.ndarray, values: np.ndarray) -> None:
    """out[index] = values for int indices (rows of an (N, 3) array, or elements)."""
    items = _as_items(out)
    if items is None:
        out[index] = values
        return
    v = np.ascontiguousarray(values, dtype=np.float64)
    if v.shape != (len(index), 3):
        v = np.ascontiguousarray(np.broadcast_to(v, (len(index), 3)))
    np.put(items, index, v.view(_ROW).reshape(-1))


def add_rows(out: np.ndarray, index: np.ndarray, values: np.ndarray) -> None:
    """out[index] += values for distinct int indices (no index repeated)."""
    put_rows(out, index, rows(out, index) + values)


def dot(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """a . b over the last axis of (..., 3) arrays, summed in the scalar order x, y, z."""
    return a[..., 0] * b[..., 0] + a[..., 1] * b[..., 1] + a[..., 2] * b[..., 2]


def max3(a: np.ndarray) -> np.ndarray:
    """Largest of the three components of (N, 3) a: a.max(axis=1)."""
    return np.maximum(np.maximum(a[:, 0], a[:, 1]), a[:, 2])


def scale(a: np.ndarray, s: np.ndarray, out: np.ndarray | None = None) -> np.ndarray:
    """a * s[:, None] for a (N, 3) and s (N,), computed column by column."""
    if out is None:
        out = np.empty(a.shape)
    for c in range(3):
        np.multiply(a[:, c], s, out=out[:, c])
    return out


def divide(a: np.ndarray, s: np.ndarray) -> np.ndarray:
    """a / s[:, None] for a (N, 3) and s (N,), column by column."""
    out = np.empty(a.shape)
    for c in range(3):
        np.divide(a[:, c], s, out=out[:, c])
    return out


def where_rows(mask: np.ndarray, a: np.ndarray) -> np.ndarray:
    """np.where(mask[:, None], a, 0.0) for a (N, 3) and mask (N,), column by column."""
    out = np.empty(a.shape)
    for c in range(3):
        np.copyto(out[:, c], np.where(mask, a[:, c], 0.0))
    return out


def axpy(s: np.ndarray, d: np.ndarray, o: np.ndarray) -> np.ndarray:
    """o + s[:, None] * d for o, d (N, 3) (either may be one (3,) row) and s (N,),
    column by column (each component rounded as in the broadcast form)."""
    out = np.empty(d.shape if d.ndim == 2 else o.shape if o.ndim == 2 else (len(s), 3))
    for c in range(3):
        col = out[:, c]
        np.multiply(s, d[..., c], out=col)
        np.add(o[..., c], col, out=col)
    return out
