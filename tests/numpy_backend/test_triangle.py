"""TriangleSet against rtpy/triangle.py: the scalar hit_t, to rounding."""

from __future__ import annotations

import numpy as np
from hypothesis import assume, given, settings

from rtpy import Triangle
from rtpy.numpy_backend.triangle import TriangleSet
from rtpy.ray import Ray

from .geometry_checks import MAT, V, arr, check_planar, planar_shape, unit_pair, vec


@settings(max_examples=300)
@given(vec, vec, vec, vec, unit_pair)
def test_triangle_t_matches_scalar(a, b, c, origin, uv):
    tri = planar_shape(lambda: Triangle(V(a), V(b), V(c), MAT))
    assume(tri is not None)
    e1, e2 = arr(tri.e1), arr(tri.e2)

    def edge_distance(o, d, t):
        r = tri._barycentric(Ray(V(o), V(d)))
        if r is None:  # the scalar missed: how far outside is the numpy hit?
            p = o + t * d - np.array(a)
            m = np.array([[e1 @ e1, e1 @ e2], [e1 @ e2, e2 @ e2]])
            bu, bv = np.linalg.solve(m, [p @ e1, p @ e2])
        else:
            bu, bv = r[1], r[2]
        return min(abs(bu), abs(bv), abs(1 - bu - bv), abs(bu - 1))

    target = np.array(a) + uv[0] * e1 + uv[1] * e2 * 0.5
    check_planar(tri, TriangleSet([tri]), origin, target, edge_distance)
