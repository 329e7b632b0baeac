"""rtpy.numpy_backend.scatter_info.ScatterBatch: N sampled bounces as arrays."""

from __future__ import annotations

import numpy as np

from rtpy.numpy_backend.scatter_info import ScatterBatch


def test_absorbed_samples_are_all_zero_and_not_alive():
    batch = ScatterBatch.absorbed(3)
    assert len(batch) == 3
    for values in (batch.direction, batch.attenuation, batch.pdf):
        assert not values.any()
    assert not batch.alive.any() and not batch.is_specular.any()


def test_alive_rows_hold_their_values_and_the_rest_is_absorbed():
    direction = np.array([[0.0, 0.0, 1.0], [0.0, 1.0, 0.0]])
    weight = np.array([[0.5, 0.5, 0.5], [0.25, 0.5, 1.0]])
    batch = ScatterBatch.alive_at(4, np.array([1, 3]), direction, weight, np.array([0.3, 0.7]))
    assert batch.alive.tolist() == [False, True, False, True]
    assert not batch.is_specular.any()
    np.testing.assert_array_equal(batch.direction[[1, 3]], direction)
    np.testing.assert_array_equal(batch.attenuation[[1, 3]], weight)
    assert batch.pdf.tolist() == [0.0, 0.3, 0.0, 0.7]
    assert not batch.direction[[0, 2]].any() and not batch.attenuation[[0, 2]].any()


def test_put_writes_a_part_into_rows_by_index_or_slice():
    part = ScatterBatch.alive_at(2, slice(None), np.eye(3)[:2], np.full((2, 3), 0.5), np.ones(2))
    part.is_specular[1] = True
    for index in (np.array([2, 0]), slice(1, 3)):
        whole = ScatterBatch.absorbed(4)
        whole.put(index, part)
        rows = np.arange(4)[index]
        np.testing.assert_array_equal(whole.direction[rows], part.direction)
        np.testing.assert_array_equal(whole.attenuation[rows], part.attenuation)
        assert whole.alive[rows].all() and whole.is_specular[rows].tolist() == [False, True]
        others = np.setdiff1d(np.arange(4), rows)
        assert not whole.alive[others].any() and not whole.direction[others].any()
