"""SphereSet against rtpy/sphere.py: the scalar hit_t, bit for bit, and the tangent."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from rtpy import Scene, Sphere, Vec3
from rtpy.numpy_backend.scene import BatchScene
from rtpy.numpy_backend.sphere import SphereSet
from rtpy.ray import Ray

from .geometry_checks import MAT, V, arr, ray_toward, vec


@settings(max_examples=300)
@given(vec, st.floats(0.05, 3.0), vec, vec)
def test_sphere_t_is_bit_identical(center, radius, origin, target):
    sphere = Sphere(V(center), radius, MAT)
    o, d = ray_toward(origin, np.array(center) + np.array(target) * radius / 4)
    s = SphereSet([sphere])
    t = s.hit_t(o[None], d[None], np.array([0]), 0.0, np.array([math.inf]))[0]
    ref = sphere.hit_t(Ray(V(o), V(d)), 0.0, math.inf)
    assert (ref is None and t == math.inf) or t == ref


def test_sphere_tangent_at_the_pole_falls_back_to_the_normal_frame():
    s = Sphere(Vec3(1, 2, 3), 2.0, MAT)
    geo = BatchScene(Scene([s]))
    geo.need_tangent = True
    o, d = np.array([[1.0, 10.0, 3.0]]), np.array([[0.0, -1.0, 0.0]])
    obj, t = geo.find_intersection(o, d)
    hits = geo.hit_batch(obj, o, d, t)
    ref = s.hit_info(Ray(V(o[0]), V(d[0])), float(t[0]))
    np.testing.assert_allclose(hits.tangent[0], arr(ref.tangent), atol=1e-15)


def test_the_cone_formulas_are_the_scalar_ones_to_the_bit():
    """one_minus_cos_max and nearer_root on arrays: rtpy.sphere's numbers, row by row."""
    from rtpy import sphere as scalar
    from rtpy.numpy_backend.sphere import nearer_root, one_minus_cos_max

    rng = np.random.default_rng(3)
    d2 = rng.uniform(1.1, 1e4, 200)
    r2 = np.ones(200)
    omc = one_minus_cos_max(r2, d2)
    cos_t = 1.0 - rng.random(200) * omc
    sin2_t = np.maximum(0.0, 1.0 - cos_t * cos_t)
    batched = nearer_root(d2, r2, np.sqrt(d2), cos_t, sin2_t)
    for i in range(200):
        a, b = float(d2[i]), float(cos_t[i])
        assert scalar.one_minus_cos_max(1.0, a) == omc[i]
        assert scalar.nearer_root(a, 1.0, math.sqrt(a), b, float(sin2_t[i])) == batched[i]
