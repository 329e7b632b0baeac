"""The "jittered" integrator: the flat colour averaged over random rays in each pixel."""

from __future__ import annotations

import math

import numpy as np

import rtpy
from rtpy import Camera, Color, Lambertian, Quad, Scene, Vec3


def two_walls() -> tuple[Scene, Camera]:
    """A red wall left of x = 0 and a blue one right of it, seen head-on by a camera
    whose middle column of pixels (of an odd width) straddles the edge."""
    red = Quad(Vec3(-2, -2, -1), Vec3(2, 0, 0), Vec3(0, 4, 0), Lambertian(Color(1, 0, 0)))
    blue = Quad(Vec3(0, -2, -1), Vec3(2, 0, 0), Vec3(0, 4, 0), Lambertian(Color(0, 0, 1)))
    camera = Camera(Vec3(0, 0, 0), Vec3(0, 0, -1), vfov=60, aspect_ratio=1.0, width=9)
    return Scene([red, blue]), camera


def test_jittered_averages_the_colours_inside_a_pixel():
    """Away from the edge every ray sees one wall: the pixel is its albedo exactly. The
    pixel on the edge mixes the two by the share of its rays that land on each side,
    half and half in expectation (a binomial count, within 5 sigma); the center
    integrator there shows one wall only."""
    scene, camera = two_walls()
    spp = 400
    image = rtpy.render(scene, camera=camera, integrator="jittered", spp=spp, seed=3).linear
    middle = camera.width // 2
    np.testing.assert_array_equal(image[:, :middle], np.broadcast_to([1, 0, 0], (9, middle, 3)))
    np.testing.assert_array_equal(image[:, middle + 1 :], np.broadcast_to([0, 0, 1], (9, 4, 3)))
    edge = image[:, middle]
    np.testing.assert_allclose(edge[:, 0] + edge[:, 2], 1.0, rtol=1e-12)
    assert (edge[:, 1] == 0).all()
    red_share = edge[:, 0].mean()
    assert abs(red_share - 0.5) < 5 * math.sqrt(0.25 / (spp * camera.height))
    center = rtpy.render(scene, camera=camera, integrator="center").linear[:, middle]
    assert {tuple(c) for c in center} <= {(1.0, 0.0, 0.0), (0.0, 0.0, 1.0)}
