"""Shapes without a batched twin go to a ScalarSet, which calls their scalar methods."""

from __future__ import annotations

import math

import numpy as np

from rtpy import Sphere, Vec3
from rtpy.interval import Interval
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
