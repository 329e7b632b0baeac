"""Tests for rtpy.sampling: generator handling, sample distributions, MIS weights."""

from __future__ import annotations

import math

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rtpy import sampling
from rtpy.sampling import (
    generator,
    make_generator,
    power_heuristic,
    random_cosine_direction,
    random_double,
    random_in_unit_disk,
    random_unit_vector,
    use_generator,
)


def draws(n: int = 8) -> list[float]:
    return [random_double() for _ in range(n)]


def test_make_generator_is_deterministic():
    a = make_generator(1, 2, 3)
    b = make_generator(1, 2, 3)
    assert [a.random() for _ in range(20)] == [b.random() for _ in range(20)]


@pytest.mark.parametrize(
    "k1, k2", [((1,), (2,)), ((1, 2), (2, 1)), ((1, 23), (12, 3)), ((0,), (0, 0)), ((5,), (-5,))]
)
def test_make_generator_differs_for_different_keys(k1, k2):
    a = make_generator(*k1)
    b = make_generator(*k2)
    assert [a.random() for _ in range(5)] != [b.random() for _ in range(5)]


def test_use_generator_installs_and_restores():
    before = generator()
    state = before.getstate()
    g = make_generator(1234)
    with use_generator(g) as installed:
        assert installed is g
        assert generator() is g
        inside = draws()
    assert generator() is before
    # The draws inside came from g, not from the generator that was in use before.
    assert before.getstate() == state
    reference = make_generator(1234)
    assert inside == [reference.random() for _ in range(8)]
    # Same key, same sequence through random_double.
    with use_generator(make_generator(1234)):
        again = draws()
    assert again == inside
    with use_generator(make_generator(1235)):
        other = draws()
    assert other != inside


def test_use_generator_nests_and_restores_after_exception():
    outer, inner = make_generator(1), make_generator(2)
    before = generator()
    with use_generator(outer):
        with pytest.raises(RuntimeError):
            with use_generator(inner):
                assert generator() is inner
                raise RuntimeError("boom")
        assert generator() is outer
    assert generator() is before
    assert sampling._generator is before


def test_random_double_range():
    with use_generator(make_generator(7)):
        xs = [random_double(2.0, 5.0) for _ in range(2000)]
    assert all(2.0 <= x < 5.0 for x in xs)
    mean = sum(xs) / len(xs)
    # Uniform on [2, 5): mean 3.5, sd 3/sqrt(12); 4 sigma of the mean.
    assert abs(mean - 3.5) < 4 * (3.0 / math.sqrt(12.0)) / math.sqrt(len(xs))


def test_random_unit_vector_has_unit_length_and_zero_mean():
    n = 5000
    with use_generator(make_generator(11)):
        vs = [random_unit_vector() for _ in range(n)]
    for v in vs:
        assert math.isclose(v.length(), 1.0, abs_tol=1e-12)
    # Uniform on the sphere: each component has mean 0 and variance 1/3.
    sd = math.sqrt(1.0 / 3.0 / n)
    for i in range(3):
        assert abs(sum(v[i] for v in vs) / n) < 4 * sd


def test_random_in_unit_disk():
    n = 5000
    with use_generator(make_generator(12)):
        ps = [random_in_unit_disk() for _ in range(n)]
    assert all(p.e2 == 0.0 and p.e0 * p.e0 + p.e1 * p.e1 <= 1.0 for p in ps)
    # Uniform by area: r^2 is uniform on [0, 1], mean 1/2, variance 1/12.
    r2 = [p.e0 * p.e0 + p.e1 * p.e1 for p in ps]
    assert abs(sum(r2) / n - 0.5) < 4 * math.sqrt(1.0 / 12.0 / n)


def test_random_cosine_direction_mean_z():
    n = 200_000
    with use_generator(make_generator(1234)):
        samples = [random_cosine_direction() for _ in range(n)]
    zs = [s.z() for s in samples]
    assert min(zs) >= 0.0
    for x, y, z in samples[:2000]:
        assert math.isclose(x * x + y * y + z * z, 1.0, abs_tol=1e-12)
    # pdf cos/pi: E[z] = 2/3, E[z^2] = 1/2, so var = 1/2 - 4/9.
    mean = sum(zs) / n
    sigma = math.sqrt((0.5 - 4.0 / 9.0) / n)
    assert abs(mean - 2.0 / 3.0) < 4.0 * sigma
    # And the azimuth is unbiased: E[x] = E[y] = 0 with var = E[x^2] = 1/4.
    sx = sum(s[0] for s in samples) / n
    sy = sum(s[1] for s in samples) / n
    assert abs(sx) < 4.0 * math.sqrt(0.25 / n)
    assert abs(sy) < 4.0 * math.sqrt(0.25 / n)


def test_power_heuristic_known_values():
    assert power_heuristic(1.0, 0.0) == 1.0
    assert power_heuristic(0.0, 1.0) == 0.0
    assert power_heuristic(2.0, 2.0) == 0.5
    assert math.isclose(power_heuristic(3.0, 1.0), 9.0 / 10.0)
    assert math.isclose(power_heuristic(1.0, 3.0), 1.0 / 10.0)


def test_power_heuristic_both_zero_is_zero_not_an_error():
    assert power_heuristic(0.0, 0.0) == 0.0


@settings(deadline=None, max_examples=80)
@given(st.floats(1e-6, 1e6), st.floats(1e-6, 1e6))
def test_power_heuristic_weights_sum_to_one(a, b):
    wa, wb = power_heuristic(a, b), power_heuristic(b, a)
    assert 0.0 <= wa <= 1.0 and 0.0 <= wb <= 1.0
    assert math.isclose(wa + wb, 1.0, rel_tol=1e-12)
    if a > b:
        assert wa > wb
