"""Shared inputs of the geometry tests: random shapes, scenes and rays, and the
conversions between Vec3 and arrays. Used by the tests in this folder."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import strategies as st

from rtpy import Lambertian, Quad, Scene, Sphere, Triangle, Vec3
from rtpy.ray import Ray

coord = st.floats(-5.0, 5.0, allow_nan=False)
vec = st.tuples(coord, coord, coord)
unit_pair = st.tuples(st.floats(-1.2, 2.2), st.floats(-1.2, 2.2))
MAT = Lambertian()


def unit(v) -> np.ndarray:
    a = np.array(v, dtype=np.float64)
    n = np.linalg.norm(a)
    return a / n if n > 1e-3 else np.array([0.0, 0.0, 1.0])


def V(a) -> Vec3:
    return Vec3(*map(float, a))


def arr(v: Vec3) -> np.ndarray:
    return np.array([v.e0, v.e1, v.e2])


def ray_toward(origin, target) -> tuple[np.ndarray, np.ndarray]:
    o = np.array(origin, dtype=np.float64)
    return o, unit(np.array(target) - o)


def planar_shape(make):
    """The quad or triangle make() builds, or None where it is degenerate (refused by
    the constructor, or of area below 1e-3): the tests assume() it is not None."""
    try:
        shape = make()
    except ValueError:
        return None
    return shape if shape.area() >= 1e-3 else None


def check_planar(shape, prims, origin, target, edge_distance) -> None:
    """For the ray from origin toward target, numpy and scalar agree on hit or miss
    (except within 1e-9 of an edge: edge_distance(o, d, t)) and on t; a ray in the
    shape's plane is skipped (which rounding wins is arbitrary)."""
    o, d = ray_toward(origin, target)
    if abs(d @ arr(shape.normal)) < 1e-3:
        return
    ref = shape.hit_t(Ray(V(o), V(d)), 0.0, math.inf)
    t_all = prims.all_t(o[None], d[None], 0.0)[0, 0]
    t_pair = prims.hit_t(o[None], d[None], np.array([0]), 0.0, np.array([math.inf]))[0]
    for t in (t_all, t_pair):
        if ref is None or t == math.inf:
            if (ref is None) != (t == math.inf):
                assert edge_distance(o, d, ref if ref is not None else t) < 1e-9  # on an edge
            continue
        assert t == pytest.approx(ref, rel=1e-12, abs=1e-12)


def random_scene(rng: np.random.Generator, n_spheres: int, n_quads: int, n_tris: int):
    objects = []
    for _ in range(n_spheres):
        objects.append(Sphere(V(rng.uniform(-4, 4, 3)), float(rng.uniform(0.05, 1.0)), MAT))
    for _ in range(n_quads):
        q = rng.uniform(-4, 4, 3)
        objects.append(Quad(V(q), V(rng.uniform(-2, 2, 3)), V(rng.uniform(-2, 2, 3)), MAT))
    for _ in range(n_tris):
        a = rng.uniform(-4, 4, 3)
        b, c = a + rng.uniform(-2, 2, 3), a + rng.normal(0, 1, 3)
        objects.append(Triangle(V(a), V(b), V(c), MAT))
    order = rng.permutation(len(objects))
    return Scene([objects[i] for i in order])


def random_rays(rng, n, spread=6.0):
    o = rng.uniform(-spread, spread, (n, 3))
    d = rng.normal(size=(n, 3))
    return o, d / np.linalg.norm(d, axis=1, keepdims=True)
