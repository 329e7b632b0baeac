"""BatchScene against rtpy/scene.py: find_intersection, find_occlusion and the hit
records, on random scenes of spheres, quads and triangles."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rtpy import Sphere, Vec3
from rtpy.interval import Interval
from rtpy.numpy_backend.hittable import BVH_THRESHOLD
from rtpy.numpy_backend.scene import BatchScene
from rtpy.ray import Ray

from .geometry_checks import MAT, V, arr, random_rays, random_scene


@pytest.mark.parametrize("sizes", [(5, 4, 3), (BVH_THRESHOLD + 40, 3, 2), (3, 60, 50), (0, 0, 0)])
def test_closest_hit_and_occlusion_match_the_scene(sizes):
    rng = np.random.default_rng(sum(sizes))
    scene = random_scene(rng, *sizes)
    geo = BatchScene(scene)
    o, d = random_rays(rng, 400)
    obj, t = geo.find_intersection(o, d)
    t_max = rng.uniform(0.0, 8.0, len(o))
    blocked = geo.find_occlusion(o, d, t_max)
    mismatches = 0
    for i in range(len(o)):
        ray = Ray(V(o[i]), V(d[i]))
        hit = scene.find_intersection(ray, Interval(0.0, math.inf))
        if hit is None:
            mismatches += obj[i] != -1
        elif obj[i] == -1 or scene.objects[obj[i]] is not hit.obj:
            mismatches += 1  # only a near-tie or an edge graze may differ
            assert obj[i] == -1 or abs(t[i] - hit.t) < 1e-9 * max(1.0, hit.t)
        else:
            assert t[i] == pytest.approx(hit.t, rel=1e-12, abs=1e-12)
        ref_blocked = scene.find_occlusion(ray, Interval(0.0, float(t_max[i])))
        mismatches += blocked[i] != ref_blocked
    assert mismatches <= 2  # rays grazing an edge, at most


def test_hit_batch_matches_hit_info_uv_and_tangent():
    rng = np.random.default_rng(3)
    scene = random_scene(rng, 20, 10, 10)
    scene.add_object(Sphere(Vec3(0, 0, 0), 1.0, MAT))  # rays from inside hit the back face
    geo = BatchScene(scene)
    geo.need_uv = geo.need_tangent = True  # Lambertians need neither: ask for both
    o, d = random_rays(rng, 1000)
    o[:100] = rng.uniform(-0.3, 0.3, (100, 3))
    obj, t = geo.find_intersection(o, d)
    h = obj >= 0
    hits = geo.hit_batch(obj[h], o[h], d[h], t[h])
    assert not hits.front_face.all() and hits.front_face.any()
    for n, i in enumerate(np.flatnonzero(h)):
        ref = scene.objects[obj[i]].hit_info(Ray(V(o[i]), V(d[i])), float(t[i]))
        np.testing.assert_allclose(hits.point[n], arr(ref.point), rtol=1e-12, atol=1e-12)
        np.testing.assert_allclose(hits.normal[n], arr(ref.normal), rtol=1e-12, atol=1e-12)
        assert hits.front_face[n] == ref.front_face
        np.testing.assert_allclose(hits.wo[n], -d[i])
        assert hits.u[n] == pytest.approx(ref.u, rel=1e-12, abs=1e-12)
        assert hits.v[n] == pytest.approx(ref.v, rel=1e-12, abs=1e-12)
        np.testing.assert_allclose(hits.tangent[n], arr(ref.tangent), rtol=1e-12, atol=1e-12)
