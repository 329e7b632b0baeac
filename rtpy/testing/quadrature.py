"""Adaptive Simpson quadrature over the cells of a 2D grid: integrals of pdf() and
of BRDF * cos over the sphere, for the chi-square and energy checks."""

from __future__ import annotations

import math
from collections.abc import Callable, Sequence

import numpy as np

__all__ = ["AdaptiveSimpson2D", "sample_spacing", "subdivide"]

# Simpson weights on 3 nodes (0, 2, 4) and of the composite rule on 5 nodes (0..4)
# of an interval of length 1.
_S3 = (1 / 6, 0.0, 4 / 6, 0.0, 1 / 6)
_S5 = (1 / 12, 4 / 12, 2 / 12, 4 / 12, 1 / 12)


class AdaptiveSimpson2D:
    """Adaptive tensor-product Simpson quadrature over the cells of a grid.

    f(x, y) returns a tuple of k floats. The grid is given by its edges; cell
    (i, j) is [x_edges[i], x_edges[i+1]] x [y_edges[j], y_edges[j+1]]. A cell is
    integrated with the composite Simpson rule on 5 x 5 nodes (S55). Replacing
    it by the plain rule on 3 nodes in x (S35) or in y (S53) estimates the error
    along each axis: e_x = |S55 - S35| / 15, e_y = |S55 - S53| / 15 (Simpson's
    error falls 16-fold when the step halves). When e_x + e_y exceeds the
    tolerance, the cell is halved along the axes that carry the error, and the
    halves are integrated with the tolerance shared among them, down to
    max_depth halvings per axis and until f has been evaluated max_evaluations
    times (then cells are accepted as they are; the error estimate says so).
    Splitting per axis matters near the poles of (theta, phi) coordinates, where
    cells are thin wedges, and for lobes that are narrow in one direction only
    (a microfacet lobe at grazing incidence).

    The tolerance of a cell with result S is max(abs_tol, rel_tol * S,
    sqrt_tol * sqrt(S)) for the largest component: the chi-square test needs
    the error of an expected count E below a fraction of sqrt(E), its noise.
    Node values are cached, so neighbouring cells and halves share them.
    """

    split_share = 0.25  # halve along an axis that carries this share of the error

    def __init__(
        self,
        f: Callable[[float, float], tuple[float, ...]],
        x_edges: Sequence[float],
        y_edges: Sequence[float],
        max_depth: int = 16,
        max_evaluations: int = 1_000_000,
    ) -> None:
        self.f = f
        self.x_edges = list(x_edges)
        self.y_edges = list(y_edges)
        self.max_depth = max_depth
        self.max_evaluations = max_evaluations
        self.res = 4 << max_depth  # node positions per cell side at the finest level
        self.cache: dict[tuple[int, int, int, int], tuple[float, ...]] = {}

    @property
    def evaluations(self) -> int:
        return len(self.cache)

    def _value(self, i: int, a: int, j: int, b: int) -> tuple[float, ...]:
        res = self.res
        if a == res:  # the same node as the first of the next cell
            i, a = i + 1, 0
        if b == res:
            j, b = j + 1, 0
        key = (i, a, j, b)
        v = self.cache.get(key)
        if v is None:
            xe, ye = self.x_edges, self.y_edges
            x = xe[i] if a == 0 else xe[i] + (xe[i + 1] - xe[i]) * (a / res)
            y = ye[j] if b == 0 else ye[j] + (ye[j + 1] - ye[j]) * (b / res)
            v = self.cache[key] = tuple(self.f(x, y))
        return v

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
        xe, ye = self.x_edges, self.y_edges
        width, height = xe[i + 1] - xe[i], ye[j + 1] - ye[j]
        if points is not None:  # to coordinates relative to the cell, in [0, 1]
            points = ((points[0] - xe[i]) / width, (points[1] - ye[j]) / height)
            if len(points[0]) == 0:
                points = None
        tols = (abs_tol, rel_tol, sqrt_tol, spacing[0] / width, spacing[1] / height)
        return self._integrate(i, j, 0, 0, 0, 0, width * height, tols, points)

    def _integrate(self, i, j, a0, b0, dx, dy, area, tols, points):
        abs_tol, rel_tol, sqrt_tol, hx, hy = tols  # hx, hy relative to the cell
        res = self.res
        sa, sb = (res >> dx) // 4, (res >> dy) // 4
        v = [[self._value(i, a0 + p * sa, j, b0 + q * sb) for q in range(5)] for p in range(5)]
        s55, s35, s53 = [], [], []
        for c in range(len(v[0][0])):
            rows = [[v[p][q][c] for q in range(5)] for p in range(5)]
            fine_y = [sum(w * x for w, x in zip(_S5, row, strict=True)) for row in rows]
            coarse_y = [sum(w * x for w, x in zip(_S3, row, strict=True)) for row in rows]
            s55.append(area * sum(w * x for w, x in zip(_S5, fine_y, strict=True)))
            s35.append(area * sum(w * x for w, x in zip(_S3, fine_y, strict=True)))
            s53.append(area * sum(w * x for w, x in zip(_S5, coarse_y, strict=True)))
        ex = max(abs(p - q) for p, q in zip(s55, s35, strict=True)) / 15.0
        ey = max(abs(p - q) for p, q in zip(s55, s53, strict=True)) / 15.0
        big = max(abs(x) for x in s55)
        tol = max(abs_tol, rel_tol * big, sqrt_tol * math.sqrt(big))
        force_x = points is not None and sa / res > hx
        force_y = points is not None and sb / res > hy
        split_x = dx < self.max_depth and (force_x or ex >= self.split_share * (ex + ey) > 0.0)
        split_y = dy < self.max_depth and (force_y or ey >= self.split_share * (ex + ey) > 0.0)
        converged = ex + ey <= tol and not (force_x or force_y)
        exhausted = len(self.cache) >= self.max_evaluations
        if converged or exhausted or not (split_x or split_y):
            # Accept, with Richardson's correction of S55's error along each axis
            # (unless it would make a non-negative integrand's integral negative).
            better = [(17.0 * p - q - r) / 15.0 for p, q, r in zip(s55, s35, s53, strict=True)]
            return (better if min(better) >= 0.0 or min(s55) < 0.0 else s55), ex + ey
        xs = (a0, a0 + 2 * sa) if split_x else (a0,)
        ys = (b0, b0 + 2 * sb) if split_y else (b0,)
        parts = len(xs) * len(ys)
        child_tols = (abs_tol / parts, rel_tol, sqrt_tol, hx, hy)
        ndx, ndy = dx + split_x, dy + split_y
        total, error = [0.0] * len(s55), 0.0
        for a in xs:
            for b in ys:
                inside = None
                if points is not None:
                    px, py = points
                    mask = (px >= a / res) & (px <= (a + 2 * sa * (1 + (not split_x))) / res)
                    mask &= (py >= b / res) & (py <= (b + 2 * sb * (1 + (not split_y))) / res)
                    if mask.any():
                        inside = (px[mask], py[mask])
                part, e = self._integrate(i, j, a, b, ndx, ndy, area / parts, child_tols, inside)
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
