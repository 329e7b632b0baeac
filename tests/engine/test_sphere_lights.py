"""rtpy.engine.sphere_lights: the scalar backend's sphere light gives the course's
Sphere.sample_hit numbers bit for bit, and is used only where it does."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

import rtpy
import rtpy.sphere
from rtpy.engine.plan import Unit
from rtpy.engine.scalar_backend import ScalarBackend, render_unit
from rtpy.engine.sphere_lights import Draws, SphereLight, prepared_scene, sample_sphere_hit
from rtpy.light import AreaLight
from rtpy.materials import DiffuseLight, Lambertian
from rtpy.sampling import generator, use_generator
from rtpy.scene import Scene
from rtpy.sphere import Sphere
from rtpy.vec3 import Color, Vec3

from .test_renderer import small_scene

coordinate = st.floats(-50.0, 50.0)
unit = st.floats(0.0, 1.0, exclude_max=True)


def numbers(sample) -> tuple:
    """Everything a sample_hit result holds, as plain floats."""
    if sample is None:
        return (None,)
    direction, pdf, hit = sample
    return (
        direction.tolist(),
        pdf,
        hit.t,
        hit.point.tolist(),
        hit.normal.tolist(),
        hit.front_face,
        hit.material,
        hit.obj,
    )


@settings(max_examples=300, deadline=None)
@given(
    st.tuples(coordinate, coordinate, coordinate),
    st.floats(1e-3, 20.0),
    st.tuples(coordinate, coordinate, coordinate),
    unit,
    unit,
)
def test_the_numbers_are_the_courses_bit_for_bit(center, radius, p, r1, r2):
    sphere = Sphere(Vec3(*center), radius, DiffuseLight(Color(1.0, 1.0, 1.0)))
    point = Vec3(*p)
    assert numbers(sample_sphere_hit(sphere, point, r1, r2)) == numbers(
        sphere.sample_hit(point, r1, r2)
    )


def test_from_inside_the_course_samples_by_area():
    sphere = Sphere(Vec3(0.0, 0.0, 0.0), 2.0, DiffuseLight(Color(1.0, 1.0, 1.0)))
    inside = Vec3(0.5, 0.2, -0.3)
    assert numbers(sample_sphere_hit(sphere, inside, 0.3, 0.8)) == numbers(
        sphere.sample_hit(inside, 0.3, 0.8)
    )


def lit_scene(light_shape: Sphere) -> Scene:
    return Scene(
        [Sphere(Vec3(0.0, -100.5, -1.0), 100.0, Lambertian(Color(0.5, 0.5, 0.5))), light_shape],
        sky=False,
    )


def test_only_a_plain_sphere_light_is_replaced_and_the_scene_is_left_alone():
    glow = DiffuseLight(Color(4.0, 4.0, 4.0))
    scene = lit_scene(Sphere(Vec3(0.0, 1.0, -1.0), 0.3, glow))
    lights = list(scene.lights)
    prepared = prepared_scene(scene)
    assert [type(light) for light in prepared.lights] == [SphereLight]
    assert prepared.lights[0].shape is scene.objects[1]
    assert scene.lights == lights and type(scene.lights[0]) is AreaLight  # untouched
    assert prepared.objects is scene.objects

    class Bigger(Sphere):
        pass

    other = lit_scene(Bigger(Vec3(0.0, 1.0, -1.0), 0.3, glow))
    assert prepared_scene(other) is other


def test_a_sphere_whose_sampling_differs_keeps_the_courses(monkeypatch):
    """An edited Sphere.sample_hit (here: the draws swapped) is what renders."""
    scene = lit_scene(Sphere(Vec3(0.0, 1.0, -1.0), 0.3, DiffuseLight(Color(4.0, 4.0, 4.0))))
    course = Sphere.sample_hit
    monkeypatch.setattr(Sphere, "sample_hit", lambda s, p, r1, r2: course(s, p, r2, r1))
    assert prepared_scene(scene) is scene


def test_a_light_whose_sampling_differs_keeps_the_courses(monkeypatch):
    """An edited AreaLight.sample (here: the draws swapped) is what renders."""
    scene = lit_scene(Sphere(Vec3(0.0, 1.0, -1.0), 0.3, DiffuseLight(Color(4.0, 4.0, 4.0))))
    assert prepared_scene(scene) is not scene
    course = AreaLight.sample

    def swapped(light, p):
        with use_generator(Draws(*reversed([generator().random() for _ in range(2)]))):
            return course(light, p)

    monkeypatch.setattr(AreaLight, "sample", swapped)
    assert prepared_scene(scene) is scene


def test_a_course_that_cannot_sample_yet_keeps_its_light(monkeypatch):
    """Before the week that writes unit_vector, the scene still renders with the
    course's light (which raises only if a render samples it)."""

    def unwritten(v):
        raise NotImplementedError("unit_vector")

    monkeypatch.setattr(rtpy.sphere, "unit_vector", unwritten)
    scene = lit_scene(Sphere(Vec3(0.0, 1.0, -1.0), 0.3, DiffuseLight(Color(4.0, 4.0, 4.0))))
    assert prepared_scene(scene) is scene


def test_a_unit_renders_the_same_sums_as_with_the_courses_light():
    scene, camera = small_scene()  # a sphere light over a ground and a metal ball
    assert any(isinstance(light, SphereLight) for light in prepared_scene(scene).lights)
    backend = ScalarBackend(scene, camera, rtpy.RenderSettings(spp=2, seed=4))
    unit = Unit(0, 0, 0, 0, camera.width, 8, 2)
    integrator = backend.make_integrator()
    sums = backend.start()(unit)
    np.testing.assert_array_equal(sums, render_unit(scene, camera, integrator, 4, unit))
    assert np.isfinite(sums).all() and sums.max() > 0.0
