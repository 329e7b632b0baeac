"""The batched ONB against rtpy/onb.py: the same frames and coordinates, bit for bit."""

from __future__ import annotations

import numpy as np

from rtpy.numpy_backend.onb import ONB, local_to_world, tangent_of
from rtpy.numpy_backend.vec3 import components, stack
from rtpy.onb import ONB as ScalarONB
from rtpy.vec3 import Vec3


def unit_rows(rng: np.random.Generator, n: int) -> np.ndarray:
    a = rng.normal(size=(n, 3))
    a[:5] = [[0, 0, 1], [0, 0, -1], [1, 0, 0], [0, -1e-300, -1], [1e-17, 0, -1]]
    return a / np.linalg.norm(a, axis=1, keepdims=True)


def test_frames_and_coordinates_are_the_scalar_ones():
    """ONB(w), from_normal_tangent (tangents off the surface, along the normal and
    nearly so), to_local, to_world, and local_to_world as ONB(w).to_world: equal to
    the last bit."""
    rng = np.random.default_rng(2)
    n = 400
    normal = unit_rows(rng, n)
    tangent = rng.normal(size=(n, 3))
    tangent[:40] = normal[:40] * rng.choice([-1.0, 1.0], (40, 1))
    tangent[40:80] = normal[40:80] + 1e-10 * rng.normal(size=(40, 3))
    d, local = rng.normal(size=(n, 3)), rng.normal(size=(3, n))
    duff = ONB(components(normal))
    frame = ONB.from_normal_tangent(components(normal), components(tangent))
    to_local = stack(*frame.to_local(components(d)))
    to_world = stack(*frame.to_world(tuple(local)))
    fused = stack(*local_to_world(components(normal), *local))
    np.testing.assert_array_equal(fused, stack(*duff.to_world(tuple(local))))
    np.testing.assert_array_equal(tangent_of(normal), stack(*duff.u))
    for i in range(n):
        w, t = Vec3(*normal[i]), Vec3(*tangent[i])
        ref_duff, ref = ScalarONB(w), ScalarONB.from_normal_tangent(w, t)
        for axis, ref_axis in zip((duff.u, duff.v), (ref_duff.u, ref_duff.v), strict=True):
            assert [c[i] for c in axis] == list(ref_axis)
        for axis, ref_axis in zip((frame.u, frame.v, frame.w), (ref.u, ref.v, ref.w), strict=True):
            assert [c[i] for c in axis] == list(ref_axis)
        assert to_local[i].tolist() == list(ref.to_local(Vec3(*d[i])))
        assert to_world[i].tolist() == list(ref.to_world(Vec3(*local[:, i])))
        assert fused[i].tolist() == list(ref_duff.to_world(Vec3(*local[:, i])))
