"""rtpy.engine.prepared_scene: the scene the scalar backend renders has FastSphere
copies and SphereLights where they give the course's numbers, renders the same sums
as the user's scene, and leaves that scene alone."""

from __future__ import annotations

import numpy as np

import rtpy
from rtpy.camera import Camera
from rtpy.engine.plan import Unit
from rtpy.engine.prepared_scene import prepared_scene
from rtpy.engine.scalar_backend import ScalarBackend, render_unit
from rtpy.engine.sphere_hits import FastSphere
from rtpy.engine.sphere_lights import SphereLight
from rtpy.light import AreaLight
from rtpy.materials import DiffuseLight, Lambertian
from rtpy.scene import Scene
from rtpy.sphere import Sphere
from rtpy.vec3 import Color, Vec3

from .test_renderer import small_scene

GLOW = DiffuseLight(Color(4.0, 4.0, 4.0))
GREY = Lambertian(Color(0.5, 0.5, 0.5))


def test_plain_spheres_and_sphere_lights_are_replaced_and_the_scene_left_alone():
    scene, _ = small_scene()  # a ground, a metal ball, a sphere light
    objects, lights = list(scene.objects), list(scene.lights)
    prepared = prepared_scene(scene)
    assert [type(obj) for obj in prepared.objects] == [FastSphere] * 3
    assert [type(light) for light in prepared.lights] == [SphereLight]
    # The light's shape is the object the rays hit: a shadow ray leaves it out.
    assert prepared.lights[0].shape is prepared.objects[2]
    assert prepared.lights[0].light.shape is prepared.objects[2]
    assert scene.objects == objects and scene.lights == lights  # untouched
    assert [type(obj) for obj in scene.objects] == [Sphere] * 3
    assert type(scene.lights[0]) is AreaLight and scene.lights[0].shape is objects[2]


def test_a_sphere_subclass_keeps_its_own_methods():
    class Bigger(Sphere):
        pass

    scene = Scene([Sphere(Vec3(0.0, -100.5, -1.0), 100.0, GREY)], sky=False)
    scene.objects.append(Bigger(Vec3(0.0, 1.0, -1.0), 0.3, GLOW))
    scene.update_lights()
    prepared = prepared_scene(scene)
    assert [type(obj) for obj in prepared.objects] == [FastSphere, Bigger]
    assert type(prepared.lights[0]) is AreaLight and prepared.lights[0] is scene.lights[0]


def test_an_edited_hit_t_renders_as_written(monkeypatch):
    scene, _ = small_scene()
    course = Sphere.hit_t
    monkeypatch.setattr(Sphere, "hit_t", lambda *args: course(*args))  # the same numbers
    assert [type(obj) for obj in prepared_scene(scene).objects] == [FastSphere] * 3
    monkeypatch.setattr(Sphere, "hit_t", lambda s, ray, t0, t1: course(s, ray, t0, t1 / 2))
    assert prepared_scene(scene).objects == scene.objects  # the user's, edited method


def sums_both_ways(scene: Scene, camera: Camera) -> tuple[np.ndarray, np.ndarray]:
    """A unit's sums rendered by the backend (the prepared scene) and by the course's
    own classes (the user's scene)."""
    backend = ScalarBackend(scene, camera, rtpy.RenderSettings(spp=2, seed=4))
    unit = Unit(0, 0, 0, 0, camera.width, 8, 2)
    course = render_unit(scene, camera, backend.make_integrator(), 4, unit)
    return backend.start()(unit), course


def test_a_unit_renders_the_same_sums_as_the_courses_classes():
    sums, course = sums_both_ways(*small_scene())
    np.testing.assert_array_equal(sums, course)
    assert np.isfinite(sums).all() and sums.max() > 0.0


def test_a_scene_searched_by_a_bvh_keeps_its_tree_and_its_sums():
    scene, camera = small_scene()
    for k in range(scene.bvh_min_objects):
        scene.objects.append(Sphere(Vec3(-1.5 + 0.3 * k, -0.35, -1.6), 0.12, GREY))
    scene.update_lights()
    prepared = prepared_scene(scene)
    assert prepared.bvh().tree is scene.bvh().tree  # not built again
    assert prepared.bvh().objects == prepared.objects
    assert all(type(obj) is FastSphere for obj in prepared.objects)
    sums, course = sums_both_ways(scene, camera)
    np.testing.assert_array_equal(sums, course)
