"""Tests for rtpy.scene: closest hit, occlusion, light lists and the background."""

from __future__ import annotations

import itertools
import math

import pytest

from rtpy.interval import Interval
from rtpy.light import AreaLight, PointLight
from rtpy.materials import Dielectric, DiffuseLight, Lambertian, Metal
from rtpy.quad import Quad
from rtpy.ray import Ray
from rtpy.scene import Scene
from rtpy.sphere import Sphere
from rtpy.triangle import Triangle
from rtpy.vec3 import Color, Vec3

from .in_list_order import in_list_order
from .vectors import V

GREY = Lambertian()


RAY = Ray(V(0, 0, 0), V(0, 0, -1))


def overlapping_objects():
    """Four objects on the -z axis; along RAY they are first hit at t = 4, 3.5, 3.8, 6."""
    a = Sphere(V(0, 0, -5), 1.0, GREY)  # front at z = -4
    b = Sphere(V(0, 0, -6), 2.5, GREY)  # front at z = -3.5 (contains most of a)
    q = Quad(V(-1, -1, -3.8), V(2, 0, 0), V(0, 2, 0), GREY)  # plane z = -3.8
    t = Triangle(V(-1, -1, -6), V(2, -1, -6), V(-1, 2, -6), GREY)  # plane z = -6
    return a, b, q, t


@pytest.mark.parametrize("order", list(itertools.permutations(range(4))))
def test_closest_hit_regardless_of_order(order):
    objs = overlapping_objects()
    scene = Scene([objs[i] for i in order])
    h = scene.find_intersection(RAY, Interval(0.001, math.inf))
    assert h is not None
    assert h.obj is objs[1]
    assert h.t == pytest.approx(3.5, rel=1e-14)
    assert h.point.tolist() == pytest.approx([0.0, 0.0, -3.5], abs=1e-12)
    assert h.front_face


@pytest.mark.parametrize(
    "interval, expected_obj, expected_t",
    [
        ((3.6, math.inf), 2, 3.8),
        ((3.9, math.inf), 0, 4.0),
        ((4.1, 5.9), None, None),  # inside both spheres, between surfaces
        ((4.1, 6.5), 0, 6.0),  # far side of sphere a and the triangle, both at z = -6
        ((6.1, math.inf), 1, 8.5),  # far side of sphere b
        ((0.0, 3.4), None, None),
        ((8.6, math.inf), None, None),  # past the far side of b (z = -8.5)
    ],
)
def test_find_intersection_respects_interval(interval, expected_obj, expected_t):
    objs = overlapping_objects()
    scene = Scene(list(objs))
    h = scene.find_intersection(RAY, Interval(*interval))
    if expected_obj is None:
        assert h is None
        return
    assert h is not None
    assert h.t == pytest.approx(expected_t, rel=1e-12)
    if expected_t == 6.0:
        # Sphere a's far side and the triangle share t = 6; either is the correct surface.
        assert h.obj in (objs[0], objs[3])
    else:
        assert h.obj is objs[expected_obj]


def test_find_intersection_in_empty_scene():
    assert Scene().find_intersection(RAY, Interval(0.0, math.inf)) is None


def test_find_occlusion():
    blocker = Sphere(V(0, 0, -5), 1.0, GREY)  # surface at t = 4 and 6
    scene = Scene([blocker])
    assert scene.find_occlusion(RAY, Interval(0.001, 10.0)) is True
    # The blocker is beyond t_max: the light at t = 3 is visible.
    assert scene.find_occlusion(RAY, Interval(0.001, 3.0)) is False
    # Behind the ray's origin: not a blocker.
    assert scene.find_occlusion(Ray(V(0, 0, 0), V(0, 0, 1)), Interval(0.001, 10.0)) is False
    assert Scene().find_occlusion(RAY, Interval(0.0, math.inf)) is False


@pytest.mark.parametrize("material", [Dielectric(1.5), Metal(Color(0.9, 0.9, 0.9), 0.0)])
def test_glass_and_metal_block_shadow_rays(material):
    scene = Scene([Sphere(V(0, 0, -5), 1.0, material)])
    assert scene.find_occlusion(RAY, Interval(0.001, 10.0)) is True


def test_area_lights_collects_emitters():
    lamp1 = Quad(V(-1, 3, -1), V(2, 0, 0), V(0, 0, 2), DiffuseLight(Color(4, 4, 4)))
    lamp2 = Sphere(V(0, 5, 0), 0.5, DiffuseLight(Color(1, 2, 3), two_sided=True))
    floor = Quad(V(-5, 0, -5), V(0, 0, 10), V(10, 0, 0), GREY)
    glass = Sphere(V(0, 1, 0), 1.0, Dielectric())
    scene = Scene([floor, lamp1, glass, lamp2])
    assert all(isinstance(a, AreaLight) for a in scene.area_lights)
    assert [a.shape for a in scene.area_lights] == [lamp1, lamp2]
    # Adding an emitter later updates the list.
    lamp3 = Triangle(V(0, 4, 0), V(1, 4, 0), V(0, 4, 1), DiffuseLight(Color(1, 1, 1)))
    scene.add_object(lamp3)
    assert [a.shape for a in scene.area_lights] == [lamp1, lamp2, lamp3]
    scene.add_object(Sphere(V(3, 1, 0), 1.0, GREY))
    assert len(scene.area_lights) == 3


def test_lights_lists_point_lights_then_area_lights():
    lamp = Quad(V(-1, 3, -1), V(2, 0, 0), V(0, 0, 2), DiffuseLight(Color(4, 4, 4)))
    p1 = PointLight(V(0, 2, 0), Color(1, 1, 1))
    p2 = PointLight(V(1, 2, 0), Color(2, 2, 2))
    ball = Sphere(V(0, 0, 0), 1.0, GREY)
    scene = Scene([ball, lamp], [p1, p2])
    lights = scene.lights
    assert len(lights) == 3
    assert lights[0] is p1 and lights[1] is p2
    assert isinstance(lights[2], AreaLight) and lights[2].shape is lamp
    assert ball not in [getattr(light, "shape", None) for light in lights]
    # Point lights only, or area lights only.
    assert Scene([ball], [p2]).lights == [p2]
    only_area = Scene([lamp]).lights
    assert len(only_area) == 1 and only_area[0].shape is lamp


def test_constant_background():
    bg = Color(0.2, 0.3, 0.4)
    scene = Scene(background=bg)
    for d in (V(0, 1, 0), V(0, -1, 0), V(1, 0.3, -2)):
        assert scene.background_radiance(d).tolist() == [0.2, 0.3, 0.4]
    assert Scene().background_radiance(V(0, 0, -1)).tolist() == [0.0, 0.0, 0.0]


def rtiow_sky(direction) -> list[float]:
    y = direction[1] / math.sqrt(sum(c * c for c in direction))
    a = 0.5 * (y + 1.0)
    return [(1 - a) * 1.0 + a * 0.5, (1 - a) * 1.0 + a * 0.7, (1 - a) * 1.0 + a * 1.0]


@pytest.mark.parametrize(
    "direction",
    [(1, 0, 0), (0, 0, -1), (0, 1, 0), (0, -1, 0), (0, 5, 0), (3, 4, 0), (0.2, -0.7, 0.4)],
)
def test_sky_gradient(direction):
    scene = Scene(background=Color(9, 9, 9), sky=True)
    got = scene.background_radiance(V(*direction))
    assert isinstance(got, Color)
    assert got.tolist() == pytest.approx(rtiow_sky(direction), abs=1e-15)


def test_sky_known_values():
    scene = Scene(sky=True)
    assert scene.background_radiance(V(1, 0, 0)).tolist() == pytest.approx([0.75, 0.85, 1.0])
    assert scene.background_radiance(V(0, 1, 0)).tolist() == pytest.approx([0.5, 0.7, 1.0])
    assert scene.background_radiance(V(0, -1, 0)).tolist() == pytest.approx([1.0, 1.0, 1.0])


@pytest.mark.parametrize("listed", [True, False])
def test_find_occlusion_can_ignore_one_object(listed):
    """A shadow ray sent to a light is not blocked by the light itself, but still by
    everything else, with or without the BVH (twelve objects use it)."""
    light = Sphere(Vec3(0, 0, -5), 1.0, Lambertian())
    wall = Sphere(Vec3(0, 0, -10), 1.0, Lambertian())
    others = [Sphere(Vec3(10 + 3 * k, 5, 0), 1.0, Lambertian()) for k in range(10)]
    scene = Scene([light, wall, *others])
    if listed:
        scene = in_list_order(scene)
    ray = Ray(Vec3(0, 0, 0), Vec3(0, 0, -1))
    full = Interval(0.0, 20.0)
    assert scene.find_occlusion(ray, full)
    assert scene.find_occlusion(ray, full, ignore=light)
    assert not scene.find_occlusion(ray, Interval(0.0, 8.0), ignore=light)
    assert scene.find_occlusion(ray, Interval(0.0, 8.0))
