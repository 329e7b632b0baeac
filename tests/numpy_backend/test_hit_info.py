"""HitBatch.take: the selected rows of every field, gathered on first read."""

from __future__ import annotations

import numpy as np

from rtpy.numpy_backend.hit_info import HitBatch, unused


def batch(n: int, rng: np.random.Generator) -> HitBatch:
    return HitBatch(
        rng.random((n, 3)),
        rng.random((n, 3)),
        rng.random((n, 3)),
        rng.random(n),
        rng.random(n) < 0.5,
        rng.random(n),
        unused(n),
        unused(n, 3),
    )


FIELDS = ("point", "normal", "wo", "t", "front_face", "u", "v", "tangent")


def test_take_gives_the_rows_of_every_field_by_index_or_mask():
    rng = np.random.default_rng(1)
    hits = batch(50, rng)
    mask = rng.random(50) < 0.4
    for k in (np.flatnonzero(mask), mask, np.array([7, 3, 3, 49])):
        part = hits.take(k)
        index = np.flatnonzero(k) if k.dtype == bool else k
        assert len(part) == len(index)
        for field in FIELDS:
            np.testing.assert_array_equal(getattr(part, field), getattr(hits, field)[index])
    # A take of a take is the composition of the two selections.
    twice = hits.take(np.arange(10, 40)).take(np.array([0, 5, 29]))
    np.testing.assert_array_equal(twice.normal, hits.normal[[10, 15, 39]])


def test_fields_are_gathered_only_when_read_and_once():
    hits = batch(20, np.random.default_rng(2))
    part = hits.take(np.array([1, 2, 3]))
    assert not set(FIELDS) & set(vars(part))  # nothing gathered yet
    normal = part.normal
    assert set(FIELDS) & set(vars(part)) == {"normal"}
    assert part.normal is normal  # kept, not gathered again
    # Unused fields stay stride-0 zeros of the new length.
    assert part.tangent.shape == (3, 3) and part.tangent.strides[0] == 0


def test_a_take_of_a_take_gathers_once_from_the_first_batch():
    rng = np.random.default_rng(3)
    hits = batch(50, rng)
    once = hits.take(np.arange(10, 40))
    mask = rng.random(30) < 0.5
    twice = once.take(mask)
    np.testing.assert_array_equal(twice.point, hits.point[10:40][mask])
    np.testing.assert_array_equal(twice.front_face, hits.front_face[10:40][mask])
    assert not set(FIELDS) & set(vars(once))  # nothing gathered into the middle batch
