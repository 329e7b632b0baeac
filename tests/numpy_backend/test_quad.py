"""QuadSet against rtpy/quad.py: the scalar hit_t, to rounding."""

from __future__ import annotations

import numpy as np
from hypothesis import assume, given, settings

from rtpy import Quad
from rtpy.numpy_backend.quad import QuadSet
from rtpy.numpy_backend.ray import ray_columns

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


def _cube_and_rays(n: int):
    """The six faces of the cube [-1, 1]^3, unclustered, and n rays from inside it."""
    faces = [
        Quad(V(q), V(u), V(v), MAT)
        for q, u, v in (
            ((-1, -1, -1), (2, 0, 0), (0, 2, 0)),
            ((-1, -1, 1), (2, 0, 0), (0, 2, 0)),
            ((-1, -1, -1), (0, 2, 0), (0, 0, 2)),
            ((1, -1, -1), (0, 2, 0), (0, 0, 2)),
            ((-1, -1, -1), (2, 0, 0), (0, 0, 2)),
            ((-1, 1, -1), (2, 0, 0), (0, 0, 2)),
        )
    ]
    rng = np.random.default_rng(17)
    o = rng.uniform(-0.9, 0.9, (n, 3))
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    return QuadSet(faces, cluster=False), o, d


def test_occlusion_inside_a_closed_box_over_several_chunks():
    # A ray from inside the cube [-1, 1]^3 meets a face at t >= 0.1; chunks of rays
    # whose t_max stops short of every face cross no quad's plane at all.
    n = 10000
    quads, o, d = _cube_and_rays(n)
    short = np.arange(n) < 4000
    t_max = np.where(short, 0.05, 10.0)
    _, k = quads.closest_hit(o, d, 0.0, t_max, any_hit=True)
    np.testing.assert_array_equal(k >= 0, ~short)


def test_closest_hit_on_handed_columns_is_closest_hit_on_rays():
    # Several chunks of rays: each chunk must use its own columns.
    n = 10000
    quads, o, d = _cube_and_rays(n)
    t_max = np.where(np.arange(n) % 3 == 0, 0.5, np.inf)
    for any_hit in (False, True):
        t, k = quads.closest_hit(o, d, 0.0, t_max, any_hit)
        tc, kc = quads.closest_hit(o, d, 0.0, t_max, any_hit, columns=ray_columns(o, d))
        assert (k >= 0).any() and (k < 0).any()
        np.testing.assert_array_equal(kc, k)
        np.testing.assert_array_equal(tc, t)
