"""The DiffuseLight kernel: emission from the front face, or from both."""

from __future__ import annotations

import numpy as np

from rtpy.materials import DiffuseLight
from rtpy.numpy_backend.materials import MaterialTable
from rtpy.vec3 import Color

from .kernel_checks import random_hits


def test_emitting_one_and_two_sided():
    lights = [DiffuseLight(Color(1.0, 2.0, 3.0)), DiffuseLight(Color(4.0, 5.0, 6.0), True)]
    rng = np.random.default_rng(0)
    hits = random_hits(rng, 4)
    hits.front_face[:] = [True, False, True, False]
    ids = np.array([0, 0, 1, 1])
    out = MaterialTable(lights).emitting(ids, hits)
    np.testing.assert_array_equal(out, [[1, 2, 3], [0, 0, 0], [4, 5, 6], [4, 5, 6]])
    np.testing.assert_array_equal(MaterialTable(lights).flat_color(ids, hits), np.ones((4, 3)))
