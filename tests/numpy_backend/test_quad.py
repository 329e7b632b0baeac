"""QuadSet against rtpy/quad.py: the scalar hit_t, to rounding."""

from __future__ import annotations

import numpy as np
from hypothesis import assume, given, settings

from rtpy import Quad
from rtpy.numpy_backend.quad import QuadSet

from .geometry_checks import MAT, V, check_planar, planar_shape, unit_pair, vec


@settings(max_examples=300)
@given(vec, vec, vec, vec, unit_pair)
def test_quad_t_matches_scalar(q, u, v, origin, ab):
    quad = planar_shape(lambda: Quad(V(q), V(u), V(v), MAT))
    assume(quad is not None)

    def edge_distance(o, d, t):
        a, b = quad._coords(V(o + t * d))
        return min(abs(a), abs(a - 1), abs(b), abs(b - 1))

    target = np.array(q) + ab[0] * np.array(u) + ab[1] * np.array(v)
    check_planar(quad, QuadSet([quad]), origin, target, edge_distance)
