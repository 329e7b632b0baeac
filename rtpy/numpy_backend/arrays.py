"""Row operations on (N,) and (N, 3) float64 arrays that avoid numpy's slow paths.

The backend stores vectors as C-contiguous (N, 3) arrays (one row per ray or hit).
For such arrays some of numpy's natural spellings run their innermost loop over the
three components, paying a per-row overhead, and are several times slower than an
equivalent spelling (numpy 2.4, N = 12,000 rows, on the development machine):

- gathering rows: a[idx] 136 us, a.take(idx, axis=0) 31 us; a[mask] 167 us,
  a.compress(mask, axis=0) 41 us;
- scattering rows: out[idx] = x 146 us, np.put on a view of each row as one
  24-byte item 36 us;
- scaling rows: a * s[:, None] 62-92 us, three column products 32 us;
- a constant row: a + c (c of shape (3,)) 100 us, three column sums 20 us.

The helpers below give the fast spelling with the meaning of the natural one. Each
takes index arrays (int) or boolean masks where it says so; results are new
C-contiguous arrays unless `out` is given.
"""

from __future__ import annotations

import numpy as np

_ROW = np.dtype((np.void, 24))  # one (3,) float64 row as a single item


def rows(a: np.ndarray, index: np.ndarray) -> np.ndarray:
    """a[index] for an int index array or a boolean mask over a's first axis."""
    if index.dtype == np.bool_:
        return a.compress(index, axis=0)
    return a.take(index, axis=0)


def at(table: np.ndarray, k: np.ndarray | int) -> np.ndarray:
    """table.take(k, axis=0): rows of a table per index; for one int k, that row
    alone (a scalar or a (3,) row, which broadcasts against the (N,) columns)."""
    return table[k] if isinstance(k, int) else table.take(k, axis=0)


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


def add_row(a: np.ndarray, c: np.ndarray) -> np.ndarray:
    """a + c for a (N, 3) and one row c (3,), column by column."""
    out = np.empty(a.shape)
    for k in range(3):
        np.add(a[:, k], c[k], out=out[:, k])
    return out
