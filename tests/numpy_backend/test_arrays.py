"""rtpy.numpy_backend.arrays: each fast spelling means what its natural numpy spelling
means, bit for bit."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from rtpy.numpy_backend import arrays

sizes = st.integers(0, 12)


def batch(n: int, seed: int) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.random.Generator]:
    """(n, 3) rows, (n,) scales and an (n,) mask, drawn from seed."""
    rng = np.random.default_rng(seed)
    return rng.normal(size=(n, 3)), rng.normal(size=n), rng.random(n) < 0.5, rng


@given(sizes, st.integers(0, 2**32 - 1))
def test_row_operations_equal_their_broadcast_forms(n, seed):
    a, s, mask, rng = batch(n, seed)
    b = rng.normal(size=(n, 3))
    index = rng.integers(0, max(n, 1), size=n) if n else np.zeros(0, dtype=np.int64)
    same = np.testing.assert_array_equal
    same(arrays.rows(a, index), a[index])
    same(arrays.rows(a, mask), a[mask])
    same(arrays.dot(a, b), (a * b).sum(axis=1) if n else np.zeros(0))
    same(arrays.scale(a, s), a * s[:, None])
    same(arrays.divide(a, s), a / s[:, None])
    same(arrays.where_rows(mask, a), np.where(mask[:, None], a, 0.0))
    same(arrays.axpy(s, b, a), a + s[:, None] * b)
    same(arrays.axpy(s, b, a[0] if n else np.zeros(3)), (a[0] if n else 0.0) + s[:, None] * b)
    if n:
        same(arrays.max3(a), a.max(axis=1))
    out = np.empty((n, 3))
    assert arrays.scale(a, s, out=out) is out


@given(sizes, st.integers(0, 2**32 - 1))
def test_writing_rows_equals_fancy_assignment(n, seed):
    a, _, mask, rng = batch(n, seed)
    index = rng.permutation(n)[: n // 2]  # distinct rows
    values = rng.normal(size=(len(index), 3))
    expected = a.copy()
    expected[index] = values
    got = a.copy()
    arrays.put_rows(got, index, values)
    np.testing.assert_array_equal(got, expected)
    arrays.put_rows(got, index, np.array([1.0, 2.0, 3.0]))  # one row for all
    expected[index] = [1.0, 2.0, 3.0]
    np.testing.assert_array_equal(got, expected)
    expected[index] += values
    arrays.add_rows(got, index, values)
    np.testing.assert_array_equal(got, expected)
    column = a[:, 0].copy()  # not (N, 3) rows: plain element assignment
    arrays.put_rows(column, index, values[:, 0])
    expected_column = a[:, 0].copy()
    expected_column[index] = values[:, 0]
    np.testing.assert_array_equal(column, expected_column)


def test_row_selections_compose():
    every = arrays.select(np.ones(4, dtype=bool))
    assert every == slice(None)  # all rows: indexing with it costs nothing
    some = arrays.select(np.array([True, False, True, True]))
    np.testing.assert_array_equal(some, [0, 2, 3])
    np.testing.assert_array_equal(arrays.compose(some, np.array([2, 0])), [3, 0])
    assert arrays.compose(some, slice(None)) is some
    np.testing.assert_array_equal(arrays.compose(every, np.array([1])), [1])
    assert arrays.true(3).tolist() == [True, True, True]
    table = np.arange(12.0).reshape(4, 3)
    np.testing.assert_array_equal(arrays.at(table, 2), table[2])
    np.testing.assert_array_equal(arrays.at(table, np.array([3, 3, 0])), table[[3, 3, 0]])
    with pytest.raises(IndexError):
        arrays.rows(table, np.array([4]))
