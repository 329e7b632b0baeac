"""The BVH and the clusters of quads give the brute-force answers."""

from __future__ import annotations

import numpy as np

from rtpy import Quad, Scene
from rtpy.numpy_backend import bvh
from rtpy.numpy_backend.bvh import _enters_box
from rtpy.numpy_backend.quad import QuadSet
from rtpy.numpy_backend.scene import BatchScene

from .geometry_checks import MAT, V, random_rays, random_scene


def test_bvh_gives_the_brute_force_answer():
    rng = np.random.default_rng(7)
    scene = random_scene(rng, 300, 80, 80)
    geo = BatchScene(scene)
    assert all(s.bvh is not None for s in geo.sets[:3])
    o, d = random_rays(rng, 2000)
    obj, t = geo.find_intersection(o, d)
    blocked = geo.find_occlusion(o, d, np.full(len(o), 3.0))
    for s in geo.sets[:3]:
        s.bvh = None
    obj2, t2 = geo.find_intersection(o, d)
    np.testing.assert_array_equal(obj, obj2)
    np.testing.assert_allclose(t, t2, rtol=1e-12)  # matrix products vs. pairs: rounding
    np.testing.assert_array_equal(blocked, geo.find_occlusion(o, d, np.full(len(o), 3.0)))


def box_quads(rng: np.random.Generator, size: float) -> list[Quad]:
    """The six faces of a randomly rotated box, as scripts/make_cornell.py writes them."""
    c = rng.uniform(-3, 3, 3)
    axes = np.linalg.qr(rng.normal(size=(3, 3)))[0] * rng.uniform(0.3, 1.0, 3) * size
    quads = []
    for k in range(3):
        e1, e2 = axes[(k + 1) % 3], axes[(k + 2) % 3]
        for side in (-0.5, 0.5):
            q = c + side * axes[k] - 0.5 * (e1 + e2)
            quads.append(Quad(V(q), V(e1), V(e2), MAT))
    return quads


def test_clustered_quads_give_the_brute_force_answer():
    rng = np.random.default_rng(11)
    room = [
        Quad(V(q), V(u), V(v), MAT)
        for q, u, v in (
            ((-6, -6, -6), (12, 0, 0), (0, 0, 12)),
            ((-6, 6, -6), (12, 0, 0), (0, 0, 12)),
            ((-6, -6, -6), (0, 12, 0), (0, 0, 12)),
            ((6, -6, -6), (0, 12, 0), (0, 0, 12)),
            ((-6, -6, 6), (12, 0, 0), (0, 12, 0)),
        )
    ]
    scene = Scene(room + box_quads(rng, 2.0) + box_quads(rng, 1.5) + box_quads(rng, 1.0))
    geo = BatchScene(scene)
    quads = geo.sets[1]
    assert quads.clusters is not None and len(quads.clusters.parts) == 4  # the room, three boxes
    o, d = random_rays(rng, 3000, spread=5.0)
    # Rays from points on the box faces (as bounces are), and rays aimed at box edges.
    corners = quads.corners()[5:].reshape(-1, 3)
    o[:500] = corners[rng.integers(0, len(corners), 500)] + rng.normal(0, 1e-3, (500, 3))
    d[500:1000] = corners[rng.integers(0, len(corners), 500)] - o[500:1000]
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    skip = np.where(rng.random(len(o)) < 0.5, rng.integers(0, len(scene.objects), len(o)), -1)
    t_max = rng.uniform(0.0, 12.0, len(o))
    obj, t = geo.find_intersection(o, d)
    blocked = geo.find_occlusion(o, d, t_max, ignore=skip)
    geo.sets[1] = QuadSet(scene.objects, cluster=False)
    assert geo.sets[1].clusters is None
    obj2, t2 = geo.find_intersection(o, d)
    np.testing.assert_array_equal(obj, obj2)
    np.testing.assert_allclose(t, t2, rtol=1e-12)
    np.testing.assert_array_equal(blocked, geo.find_occlusion(o, d, t_max, ignore=skip))


def test_slab_test_answers_alike_in_any_chunking(monkeypatch):
    rng = np.random.default_rng(13)
    lo, hi = np.array([-1.0, -0.5, 0.0]), np.array([1.0, 0.5, 2.0])
    o, d = random_rays(rng, 3000, spread=4.0)
    d[:10, 0] = 0.0  # parallel to a slab: inv = inf
    # Rays aimed at points inside the box enter it before reaching them, unless the
    # point lies behind t_min; rays from outside aimed away never enter it.
    target = rng.uniform(lo, hi, (3000, 3))
    aimed = np.arange(1000, 2000)
    d[aimed] = target[aimed] - o[aimed]
    dist = np.linalg.norm(d[aimed], axis=1)
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    away = np.arange(2000, 3000)
    outside = ((o[away] < lo) | (o[away] > hi)).any(axis=1)
    d[away] = np.where(outside[:, None], o[away] - target[away], d[away])
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    t_max = rng.uniform(0.0, 10.0, 3000)
    t_max[aimed] = dist + 1e-9
    oc = np.ascontiguousarray(o.T)
    with np.errstate(divide="ignore"):
        inv = 1.0 / np.ascontiguousarray(d.T)
    whole = _enters_box(oc, inv, lo, hi, 0.0, t_max)
    assert whole[aimed].all()
    assert not whole[away[outside]].any()
    monkeypatch.setattr(bvh, "BOX_CHUNK", 7)
    np.testing.assert_array_equal(_enters_box(oc, inv, lo, hi, 0.0, t_max), whole)
