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


def test_a_ray_in_a_quads_plane_still_finds_the_next_quad():
    # The ray lies in the first quad's plane: its t there is 0 / 0 = nan, a miss.
    floor = Quad(V((-5, -5, 0)), V((10, 0, 0)), V((0, 10, 0)), MAT)
    wall = Quad(V((3, -5, -5)), V((0, 10, 0)), V((0, 0, 10)), MAT)
    quads = QuadSet([floor, wall], cluster=False)
    o = np.array([[0.0, 0.0, 0.0], [0.0, 1.0, 1.0]])
    d = np.array([[1.0, 0.0, 0.0], [1.0, 0.0, 0.0]])
    for any_hit in (False, True):
        t, k = quads.closest_hit(o, d, 0.0, np.full(2, np.inf), any_hit)
        np.testing.assert_array_equal(k, [1, 1])
        np.testing.assert_allclose(t, [3.0, 3.0], rtol=1e-15)
