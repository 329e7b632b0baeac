"""Adaptive Simpson quadrature over the cells of a 2D grid: integrals of pdf() and
of BRDF * cos over the sphere, for the chi-square and energy checks.

The integrand is batched, f(xs, ys) -> (m, k) values, and many cells are
integrated at once, breadth first: each level of refinement evaluates, in one
call, every node the pending cells need that is not cached yet, then accepts or
halves each cell. A material in another process is then asked once per level, not
once per node.
"""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence
from dataclasses import dataclass

import numpy as np

__all__ = [
    "AdaptiveSimpson2D",
    "CellRequest",
    "integrate_cells",
    "per_point",
    "sample_spacing",
    "subdivide",
]

# f(xs, ys) -> (m, k): k values at each of the m nodes (xs[r], ys[r]).
Integrand = Callable[[np.ndarray, np.ndarray], np.ndarray]

# Simpson weights on 3 nodes (0, 2, 4) and of the composite rule on 5 nodes (0..4)
# of an interval of length 1.
_S3 = (1 / 6, 0.0, 4 / 6, 0.0, 1 / 6)
_S5 = (1 / 12, 4 / 12, 2 / 12, 4 / 12, 1 / 12)
_STEPS = np.arange(5)


def per_point(f: Callable[[float, float], Sequence[float]]) -> Integrand:
    """The batched integrand of a per-point one, f(x, y) -> k floats."""

    def batched(xs: np.ndarray, ys: np.ndarray) -> np.ndarray:
        rows = [tuple(f(x, y)) for x, y in zip(xs.tolist(), ys.tolist(), strict=True)]
        return np.array(rows, dtype=float).reshape(len(rows), -1)

    return batched


@dataclass
class CellRequest:
    """The integral over cell (i, j) of a grid, to the tolerance max(abs_tol,
    rel_tol * S, sqrt_tol * sqrt(S)); points and spacing force refinement (see
    AdaptiveSimpson2D.cell)."""

    i: int
    j: int
    abs_tol: float
    rel_tol: float = 0.0
    sqrt_tol: float = 0.0
    points: tuple[np.ndarray, np.ndarray] | None = None
    spacing: tuple[float, float] = (0.0, 0.0)


class AdaptiveSimpson2D:
    """Adaptive tensor-product Simpson quadrature over the cells of a grid.

    f(xs, ys) returns k values per node, shape (m, k) (per_point makes one of a
    function of one point). The grid is given by its edges; cell (i, j) is
    [x_edges[i], x_edges[i+1]] x [y_edges[j], y_edges[j+1]]. A cell is
    integrated with the composite Simpson rule on 5 x 5 nodes (S55). Replacing
    it by the plain rule on 3 nodes in x (S35) or in y (S53) estimates the error
    along each axis: e_x = |S55 - S35| / 15, e_y = |S55 - S53| / 15 (Simpson's
    error falls 16-fold when the step halves). When e_x + e_y exceeds the
    tolerance, the cell is halved along the axes that carry the error, and the
    halves are integrated with the tolerance shared among them, down to
    max_depth halvings per axis. Splitting per axis matters near the poles of
    (theta, phi) coordinates, where cells are thin wedges, and for lobes that
    are narrow in one direction only (a microfacet lobe at grazing incidence).

    The tolerance of a cell with result S is max(abs_tol, rel_tol * S,
    sqrt_tol * sqrt(S)) for the largest component: the chi-square test needs
    the error of an expected count E below a fraction of sqrt(E), its noise.
    Node values are cached, so neighbouring cells, halves and later requests
    share them.

    Cells are refined breadth first (integrate_cells). f is evaluated at most
    about max_evaluations times: a cell is halved only while its halves' new
    nodes fit in that budget (the requested cells' own nodes are always
    evaluated); past it cells are accepted as they are, and the error estimate
    says the tolerance was not met.
    """

    split_share = 0.25  # halve along an axis that carries this share of the error

    def __init__(
        self,
        f: Integrand,
        x_edges: Sequence[float],
        y_edges: Sequence[float],
        max_depth: int = 16,
        max_evaluations: int = 1_000_000,
    ) -> None:
        self.f = f
        self.x_edges = [float(x) for x in x_edges]
        self.y_edges = [float(y) for y in y_edges]
        self.max_depth = max_depth
        self.max_evaluations = max_evaluations
        self.res = 4 << max_depth  # node positions per cell side at the finest level
        self._row = len(self.y_edges) * self.res  # key stride of one x position
        if len(self.x_edges) * self.res * self._row >= 2**63:
            raise ValueError("max_depth: too deep for a grid this large")
        self._xe = np.array([*self.x_edges, self.x_edges[-1]])
        self._ye = np.array([*self.y_edges, self.y_edges[-1]])
        self.cache: dict[int, int] = {}  # node key -> its row in self._values
        self._values = np.zeros((0, 0))

    @property
    def evaluations(self) -> int:
        return len(self.cache)

    def cell(
        self,
        i: int,
        j: int,
        abs_tol: float,
        rel_tol: float = 0.0,
        sqrt_tol: float = 0.0,
        points: tuple[np.ndarray, np.ndarray] | None = None,
        spacing: tuple[float, float] = (0.0, 0.0),
    ) -> tuple[list[float], float]:
        """(integral per component, estimated absolute error) over cell (i, j).

        points (x and y coordinates) and spacing (hx, hy) force refinement: every
        part of the cell that holds one of the points is split until its nodes
        are at most hx apart in x and hy apart in y, whatever the error estimate
        says. chi2_test passes the samples of a bin this way, so that a lobe
        narrower than the node spacing cannot hide between the nodes.
        """
        return self.cells([CellRequest(i, j, abs_tol, rel_tol, sqrt_tol, points, spacing)])[0]

    def cells(self, requests: Sequence[CellRequest]) -> list[tuple[list[float], float]]:
        """cell() for every request, all refined together."""
        return integrate_cells([(self, r) for r in requests])

    # --- nodes ---------------------------------------------------------------------------

    def _keys(self, i, a, j, b) -> np.ndarray:
        """The cache keys of nodes (integer arrays: cell i, position a in it, ...)."""
        res = self.res
        return (i * res + a) * self._row + (j * res + b)

    def _coordinates(self, keys: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        res = self.res
        ia, jb = np.divmod(keys, self._row)
        i, a = np.divmod(ia, res)
        j, b = np.divmod(jb, res)
        xe, ye = self._xe, self._ye
        # As x = xe[i] + (xe[i + 1] - xe[i]) * (a / res), and exactly xe[i] on an edge.
        x = np.where(a == 0, xe[i], xe[i] + (xe[i + 1] - xe[i]) * (a / res))
        y = np.where(b == 0, ye[j], ye[j] + (ye[j + 1] - ye[j]) * (b / res))
        return x, y

    def _store(self, keys: list[int], values: np.ndarray) -> None:
        values = np.asarray(values, dtype=float).reshape(len(keys), -1)
        if not self.cache:
            self._values = values.copy()
        else:
            self._values = np.concatenate([self._values, values])
        start = len(self.cache)
        self.cache.update(zip(keys, range(start, start + len(keys)), strict=True))


def _wsum(weights: Sequence[float], v: np.ndarray) -> np.ndarray:
    """sum(w * x for w, x in zip(weights, v)) over the last axis, in that order (as
    Python's sum adds), so that the results are the same numbers."""
    total = 0.0 + weights[0] * v[..., 0]
    for t in range(1, 5):
        total = total + weights[t] * v[..., t]
    return total


class _Pending:
    """The cells of one integrator waiting for a round: parallel lists."""

    def __init__(self) -> None:
        self.cells: list[tuple] = []  # (i, j, a0, b0, dx, dy, area, tols, points, slot, parent)

    def add(self, *cell) -> None:
        self.cells.append(cell)


def integrate_cells(
    jobs: Sequence[tuple[AdaptiveSimpson2D, CellRequest]],
    evaluate: Callable[[list[tuple[AdaptiveSimpson2D, np.ndarray, np.ndarray]]], list]
    | None = None,
) -> list[tuple[list[float], float]]:
    """(integral per component, estimated error) for every (integrator, request),
    all cells refined together, breadth first: each round evaluates every node the
    pending cells need that is not cached, then accepts or halves each cell.

    evaluate(batches) gets [(integrator, xs, ys), ...], the new nodes of each
    integrator of a round, and returns their values in that order; by default each
    integrator's f is called. Integrators whose integrands share a material pass
    one evaluate that asks it once per round.
    """
    pending: dict[int, _Pending] = {}
    quads: dict[int, AdaptiveSimpson2D] = {}
    roots = []
    for quad, r in jobs:
        xe, ye = quad.x_edges, quad.y_edges
        width, height = xe[r.i + 1] - xe[r.i], ye[r.j + 1] - ye[r.j]
        points = r.points
        if points is not None:  # to coordinates relative to the cell, in [0, 1]
            points = ((points[0] - xe[r.i]) / width, (points[1] - ye[r.j]) / height)
            if len(points[0]) == 0:
                points = None
        tols = (r.abs_tol, r.rel_tol, r.sqrt_tol, r.spacing[0] / width, r.spacing[1] / height)
        slot = [None, 0.0, None]  # value, error, children
        roots.append(slot)
        quads[id(quad)] = quad
        pending.setdefault(id(quad), _Pending()).add(
            r.i, r.j, 0, 0, 0, 0, width * height, tols, points, slot, None
        )
    while pending:
        nodes = {q: _node_keys(quads[q], p.cells) for q, p in pending.items()}
        _keep_to_budget(quads, pending, nodes)
        _evaluate_missing(quads, nodes, evaluate)
        after: dict[int, _Pending] = {}
        for q, p in pending.items():
            _round(quads[q], p.cells, nodes[q], after.setdefault(q, _Pending()))
        pending = {q: p for q, p in after.items() if p.cells}
    return [_fold(slot) for slot in roots]


def _node_keys(quad: AdaptiveSimpson2D, cells: list[tuple]) -> np.ndarray:
    """(c, 5, 5) keys of the nodes of each cell, node (p, q) at (a0 + p sa, b0 + q sb)."""
    res = quad.res
    i = np.array([c[0] for c in cells], dtype=np.int64)[:, None, None]
    j = np.array([c[1] for c in cells], dtype=np.int64)[:, None, None]
    a0 = np.array([c[2] for c in cells], dtype=np.int64)[:, None, None]
    b0 = np.array([c[3] for c in cells], dtype=np.int64)[:, None, None]
    sa = (res >> np.array([c[4] for c in cells], dtype=np.int64)[:, None, None]) // 4
    sb = (res >> np.array([c[5] for c in cells], dtype=np.int64)[:, None, None]) // 4
    a = a0 + _STEPS[None, :, None] * sa
    b = b0 + _STEPS[None, None, :] * sb
    end_a, end_b = a == res, b == res  # the same node as the first of the next cell
    i, a = np.where(end_a, i + 1, i), np.where(end_a, 0, a)
    j, b = np.where(end_b, j + 1, j), np.where(end_b, 0, b)
    return quad._keys(i, a, j, b)


def _missing(quad: AdaptiveSimpson2D, keys: np.ndarray) -> list[int]:
    cache = quad.cache
    return [k for k in dict.fromkeys(keys.ravel().tolist()) if k not in cache]


def _keep_to_budget(quads, pending, nodes) -> None:
    """Where a round's new nodes would take an integrator past max_evaluations, keep
    the halves of split cells, in order, while they fit; the other split cells are
    accepted as they were (their halves dropped)."""
    for q, p in pending.items():
        quad = quads[q]
        room = quad.max_evaluations - len(quad.cache)
        if len(_missing(quad, nodes[q])) <= room:
            continue
        admitted: set[int] = set()
        keep = []
        groups: dict[int, list[int]] = {}
        for k, cell in enumerate(p.cells):
            groups.setdefault(id(cell[10]) if cell[10] is not None else -k - 1, []).append(k)
        for members in groups.values():
            parent = p.cells[members[0]][10]
            new = set(_missing(quad, nodes[q][members])) - admitted
            if parent is None or len(admitted) + len(new) <= room:
                admitted |= new
                keep += members
            else:  # accept the parent as it was
                parent[0], parent[1], parent[2] = parent[3], parent[4], None
        keep.sort()
        p.cells = [p.cells[k] for k in keep]
        nodes[q] = nodes[q][keep]


def _evaluate_missing(quads, nodes, evaluate) -> None:
    batches, new_keys = [], []
    for q, keys in nodes.items():
        quad = quads[q]
        missing = _missing(quad, keys)
        if missing:
            xs, ys = quad._coordinates(np.array(missing, dtype=np.int64))
            batches.append((quad, xs, ys))
            new_keys.append(missing)
    if not batches:
        return
    if evaluate is None:
        values = [quad.f(xs, ys) for quad, xs, ys in batches]
    else:
        values = evaluate(batches)
    for (quad, _, _), keys, v in zip(batches, new_keys, values, strict=True):
        quad._store(keys, v)


def _round(quad: AdaptiveSimpson2D, cells: list[tuple], keys: np.ndarray, after: _Pending):
    """Accept or halve every pending cell of one integrator (its nodes are cached)."""
    if not cells:
        return
    res, cache = quad.res, quad.cache
    rows = np.array([cache[k] for k in keys.ravel().tolist()]).reshape(keys.shape)
    v = quad._values[rows]  # (c, p, q, k)
    area = np.array([c[6] for c in cells])[:, None]
    fine_y = _wsum(_S5, v.transpose(0, 1, 3, 2))  # (c, p, k)
    coarse_y = _wsum(_S3, v.transpose(0, 1, 3, 2))
    s55 = area * _wsum(_S5, fine_y.transpose(0, 2, 1))  # (c, k)
    s35 = area * _wsum(_S3, fine_y.transpose(0, 2, 1))
    s53 = area * _wsum(_S5, coarse_y.transpose(0, 2, 1))
    ex = np.abs(s55 - s35).max(axis=1) / 15.0
    ey = np.abs(s55 - s53).max(axis=1) / 15.0
    big = np.abs(s55).max(axis=1)
    tols = np.array([c[7] for c in cells])  # abs_tol, rel_tol, sqrt_tol, hx, hy
    tol = np.maximum(np.maximum(tols[:, 0], tols[:, 1] * big), tols[:, 2] * np.sqrt(big))
    dx = np.array([c[4] for c in cells])
    dy = np.array([c[5] for c in cells])
    guided = np.array([c[8] is not None for c in cells])
    force_x = guided & ((res >> dx) // 4 / res > tols[:, 3])
    force_y = guided & ((res >> dy) // 4 / res > tols[:, 4])
    share = quad.split_share * (ex + ey)
    split_x = (dx < quad.max_depth) & (force_x | ((ex >= share) & (share > 0.0)))
    split_y = (dy < quad.max_depth) & (force_y | ((ey >= share) & (share > 0.0)))
    converged = (ex + ey <= tol) & ~(force_x | force_y)
    exhausted = len(cache) >= quad.max_evaluations
    accept = converged | exhausted | ~(split_x | split_y)
    # Accepted, with Richardson's correction of S55's error along each axis (unless
    # it would make a non-negative integrand's integral negative).
    better = (17.0 * s55 - s35 - s53) / 15.0
    corrected = (better.min(axis=1) >= 0.0) | (s55.min(axis=1) < 0.0)
    value = np.where(corrected[:, None], better, s55).tolist()
    error = (ex + ey).tolist()
    for k, cell in enumerate(cells):
        slot = cell[9]
        if accept[k]:
            slot[0], slot[1] = value[k], error[k]
            continue
        slot[2:] = [[], value[k], error[k]]  # children; the cell as it is, if they don't fit
        i, j, a0, b0, cdx, cdy, carea, (abs_tol, rel_tol, sqrt_tol, hx, hy), points = cell[:9]
        sx, sy = bool(split_x[k]), bool(split_y[k])
        sa, sb = (res >> cdx) // 4, (res >> cdy) // 4
        xs = (a0, a0 + 2 * sa) if sx else (a0,)
        ys = (b0, b0 + 2 * sb) if sy else (b0,)
        parts = len(xs) * len(ys)
        child_tols = (abs_tol / parts, rel_tol, sqrt_tol, hx, hy)
        for a in xs:
            for b in ys:
                inside = None
                if points is not None:
                    px, py = points
                    mask = (px >= a / res) & (px <= (a + 2 * sa * (1 + (not sx))) / res)
                    mask &= (py >= b / res) & (py <= (b + 2 * sb * (1 + (not sy))) / res)
                    if mask.any():
                        inside = (px[mask], py[mask])
                child = [None, 0.0, None]
                slot[2].append(child)
                after.add(
                    i, j, a, b, cdx + sx, cdy + sy, carea / parts, child_tols, inside, child, slot
                )


def _fold(slot: list) -> tuple[list[float], float]:
    """A cell's integral and error: its own, or its parts' summed in order."""
    if slot[2] is None:
        return slot[0], slot[1]
    total, error = None, 0.0
    for child in slot[2]:
        part, e = _fold(child)
        total = [0.0] * len(part) if total is None else total
        total = [t + x for t, x in zip(total, part, strict=True)]
        error += e
    return total, error


def subdivide(edges: Sequence[float], max_width: float) -> tuple[list[float], list[int]]:
    """Split every interval of `edges` into equal parts no wider than max_width.
    Returns the new edges and, for every new interval, the index of the old one."""
    new_edges, owner = [edges[0]], []
    for k in range(len(edges) - 1):
        lo, hi = edges[k], edges[k + 1]
        m = max(1, math.ceil((hi - lo) / max_width - 1e-9))
        for s in range(1, m + 1):
            new_edges.append(hi if s == m else lo + (hi - lo) * s / m)
            owner.append(k)
    return new_edges, owner


def sample_spacing(theta: np.ndarray, phi: np.ndarray) -> tuple[float, float]:
    """Node spacing in theta and in phi: a third of the spread of the samples'
    directions, so that nodes that close cannot miss a lobe the samples found."""
    return (max(float(np.std(theta)), 1e-6) / 3.0, max(float(np.std(phi)), 1e-6) / 3.0)
