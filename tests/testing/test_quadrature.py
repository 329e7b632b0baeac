"""Tests for rtpy.testing.quadrature: adaptive Simpson quadrature over grid cells."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rtpy.testing import AdaptiveSimpson2D
from rtpy.testing.quadrature import CellRequest, integrate_cells, per_point


def test_adaptive_simpson_is_accurate_for_smooth_and_peaked_integrands():
    def smooth(x, y):
        return (math.sin(x) * math.cos(y), 1.0)

    quad = AdaptiveSimpson2D(per_point(smooth), [0.0, 0.5, math.pi / 2], [0.0, math.pi / 2])
    total = [0.0, 0.0]
    for i in range(2):
        value, error = quad.cell(i, 0, 1e-10)
        total = [t + v for t, v in zip(total, value, strict=True)]
    assert total[0] == pytest.approx(1.0, abs=1e-12)
    assert total[1] == pytest.approx((math.pi / 2) ** 2, rel=1e-14)

    # A Gaussian 10 times narrower than the cell, off its nodes: adaptivity finds it.
    def gaussian(s):
        def f(x, y):
            return (math.exp(-((x - 0.3137) ** 2 + (y - 0.7071) ** 2) / (2 * s * s)),)

        return f

    quad = AdaptiveSimpson2D(per_point(gaussian(0.05)), [0.0, 0.5, 1.0], [0.0, 0.5, 1.0])
    total = sum(quad.cell(i, j, 1e-9)[0][0] for i in range(2) for j in range(2))
    assert total == pytest.approx(2 * math.pi * 0.05**2, rel=1e-7)

    # 250 times narrower, it hides between the nodes, unless points drawn from it
    # guide the refinement (as chi2_test does with the samples of a bin).
    s = 0.002
    rng = np.random.default_rng(1)
    xs, ys = rng.normal(0.3137, s, 200), rng.normal(0.7071, s, 200)
    quad = AdaptiveSimpson2D(per_point(gaussian(s)), [0.0, 1.0], [0.0, 1.0])
    value, _ = quad.cell(0, 0, 1e-9, points=(xs, ys), spacing=(s / 3, s / 3))
    assert value[0] == pytest.approx(2 * math.pi * s * s, rel=1e-6)
    # A uniform grid with nodes s / 3 apart would take (3 / s)^2 = 2.25e6 evaluations.
    assert quad.evaluations < 0.1 * (3 / s) ** 2

    # An evaluation budget stops the refinement (of a step, which never converges):
    # cells are halved while their halves' new nodes fit in it.
    quad = AdaptiveSimpson2D(per_point(lambda x, y: (float(x > y),)), [0.0, 1.0], [0.0, 1.0])
    quad.max_evaluations = 3000
    value, error = quad.cell(0, 0, 1e-15)
    assert 2500 <= quad.evaluations <= 3000
    # It promises no accuracy then, only a value the integrand allows and an error
    # estimate that says the tolerance was not met.
    assert 0.0 <= value[0] <= 1.0 and error > 1e-15


def test_many_cells_at_once_give_each_cell_its_own_result_in_few_calls():
    def lobe(x, y):
        return (math.exp(-((x - 0.41) ** 2 + (y - 0.57) ** 2) / (2 * 0.03**2)), x * y)

    calls = []

    def counted(xs, ys):
        calls.append(len(xs))
        return per_point(lobe)(xs, ys)

    edges = [0.0, 0.25, 0.5, 0.75, 1.0]
    one_by_one = []
    for i in range(4):
        for j in range(4):
            quad = AdaptiveSimpson2D(per_point(lobe), edges, edges)
            one_by_one.append(quad.cell(i, j, 1e-9))
    together = AdaptiveSimpson2D(counted, edges, edges)
    requests = [CellRequest(i, j, 1e-9) for i in range(4) for j in range(4)]
    # The same local rule, the sums in the same order: the same numbers.
    assert together.cells(requests) == one_by_one
    # One call per round, a round per level of refinement (at most 2 * max_depth + 1).
    assert len(calls) <= 2 * together.max_depth + 1
    assert sum(calls) == together.evaluations  # no node asked twice
    # Two integrators in one run share one evaluate per round.
    other = AdaptiveSimpson2D(per_point(lobe), edges, edges)
    rounds = []

    def evaluate(batches):
        rounds.append(len(batches))
        return [quad.f(xs, ys) for quad, xs, ys in batches]

    mine = AdaptiveSimpson2D(counted, edges, edges)
    jobs = [(quad, r) for r in requests for quad in (mine, other)]
    results = integrate_cells(jobs, evaluate)
    assert results[1::2] == one_by_one and max(rounds) == 2
