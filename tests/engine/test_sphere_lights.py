"""rtpy.engine.sphere_lights: the scalar backend's sphere light gives the course's
Sphere.sample_hit numbers bit for bit, and says where it does (matches)."""

from __future__ import annotations

from hypothesis import given, settings
from hypothesis import strategies as st

import rtpy
import rtpy.sphere
from rtpy.engine.sphere_lights import Draws, matches, sample_sphere_hit
from rtpy.light import AreaLight
from rtpy.materials import DiffuseLight, Lambertian
from rtpy.sampling import generator, use_generator
from rtpy.scene import Scene
from rtpy.sphere import Sphere
from rtpy.vec3 import Color, Vec3

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


def test_a_sphere_whose_sampling_differs_keeps_the_courses(monkeypatch):
    """An edited Sphere.sample_hit (here: the draws swapped) is what renders."""
    scene = lit_scene(Sphere(Vec3(0.0, 1.0, -1.0), 0.3, DiffuseLight(Color(4.0, 4.0, 4.0))))
    course = Sphere.sample_hit
    assert matches(scene.lights[0])
    monkeypatch.setattr(Sphere, "sample_hit", lambda s, p, r1, r2: course(s, p, r2, r1))
    assert not matches(scene.lights[0])


def test_a_light_whose_sampling_differs_keeps_the_courses(monkeypatch):
    """An edited AreaLight.sample (here: the draws swapped) is what renders."""
    scene = lit_scene(Sphere(Vec3(0.0, 1.0, -1.0), 0.3, DiffuseLight(Color(4.0, 4.0, 4.0))))
    assert matches(scene.lights[0])
    course = AreaLight.sample

    def swapped(light, p):
        with use_generator(Draws(*reversed([generator().random() for _ in range(2)]))):
            return course(light, p)

    monkeypatch.setattr(AreaLight, "sample", swapped)
    assert not matches(scene.lights[0])


def test_a_course_that_cannot_sample_yet_keeps_its_light(monkeypatch):
    """Before the week that writes unit_vector, the scene still renders with the
    course's light (which raises only if a render samples it)."""

    def unwritten(v):
        raise NotImplementedError("unit_vector")

    monkeypatch.setattr(rtpy.sphere, "unit_vector", unwritten)
    scene = lit_scene(Sphere(Vec3(0.0, 1.0, -1.0), 0.3, DiffuseLight(Color(4.0, 4.0, 4.0))))
    assert not matches(scene.lights[0])
