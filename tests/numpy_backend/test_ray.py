"""Spawned rays against rtpy/ray.py: the same origins, bit for bit."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings

from rtpy.numpy_backend.ray import offset_scale, spawn_origins
from rtpy.ray import offset_scale as scalar_offset_scale
from rtpy.ray import spawn_ray

from .geometry_checks import V, arr, vec


@settings(max_examples=200)
@given(vec, vec, vec)
def test_spawn_origins_are_spawn_ray(point, normal, direction):
    p, n, w = (np.array(x, dtype=np.float64)[None] for x in (point, normal, direction))
    ref = spawn_ray(V(point), V(normal), V(direction))
    np.testing.assert_array_equal(spawn_origins(p, n, w)[0], arr(ref.origin))
    assert offset_scale(p)[0] == scalar_offset_scale(V(point))
