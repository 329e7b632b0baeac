"""Shapes without a batched twin go to a ScalarSet, which calls their scalar methods."""

from __future__ import annotations

import math

import numpy as np

from rtpy import Sphere, Vec3
from rtpy.interval import Interval
from rtpy.numpy_backend.hittable import nearest
from rtpy.numpy_backend.scene import BatchScene
from rtpy.ray import Ray

from .geometry_checks import MAT, V, random_rays, random_scene


class ScalarOnlySphere(Sphere):
    """A shape the batched code does not know: intersected by its scalar methods."""


def test_unknown_shapes_use_their_scalar_methods():
    rng = np.random.default_rng(5)
    scene = random_scene(rng, 4, 2, 2)
    scene.add_object(ScalarOnlySphere(Vec3(0, 0, 0), 1.5, MAT))
    geo = BatchScene(scene)
    assert geo.sets[3] is not None
    o, d = random_rays(rng, 200)
    obj, t = geo.find_intersection(o, d)
    for i in range(len(o)):
        hit = scene.find_intersection(Ray(V(o[i]), V(d[i])), Interval(0.0, math.inf))
        assert (hit is None and obj[i] == -1) or scene.objects[obj[i]] is hit.obj
    h = obj >= 0
    hits = geo.hit_batch(obj[h], o[h], d[h], t[h])
    assert np.all(np.einsum("ij,ij->i", hits.normal, hits.wo) >= 0)


def test_nearest_is_the_min_and_the_first_argmin():
    rng = np.random.default_rng(9)
    for k, n in ((1, 5), (6, 3000), (24, 700), (130, 50)):
        t = rng.integers(0, 4, (k, n)).astype(np.float64)  # many ties
        t[rng.random((k, n)) < 0.3] = math.inf
        t[:, :3] = math.inf  # rays that hit nothing
        for layout in (t, np.ascontiguousarray(t.T).T):  # (K, N) rows, or all_t's transpose
            tj, j = nearest(layout)
            np.testing.assert_array_equal(tj, t.min(axis=0))
            np.testing.assert_array_equal(j, t.argmin(axis=0))
            assert j.dtype == np.int64
