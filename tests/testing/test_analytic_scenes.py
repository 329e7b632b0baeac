"""The analytic scenes' exact images: converged quadrature, the closed forms, and
what each scene shows."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rtpy.testing.analytic_scenes import (
    ANALYTIC_SCENES,
    GLOW_LE,
    GLOW_RHO,
    PLANE_ALBEDO,
    SKY_BAND,
    SKY_RADIANCE,
    analytic_scene,
    pixel_average,
    pixels_fully_off_sphere,
    pixels_fully_on_sphere,
)


@pytest.mark.parametrize("name", ["plane_point_light", "plane_sphere_light"])
def test_pixel_averages_are_converged(name):
    """The Gauss-Legendre pixel average of order 8 (what exact() uses) agrees with
    order 16 to 1e-10: the integrands are smooth inside every pixel (the camera
    sees only the plane)."""
    a = analytic_scene(name)
    cam = a.camera.with_width(40)
    image, mask = a.exact(cam, 4)
    assert mask.all() and image.min() > 0
    fine = pixel_average(cam, a.ray_radiance, order=16)
    np.testing.assert_allclose(image, fine, rtol=1e-10)
    centre = pixel_average(cam, a.ray_radiance, order=1)  # one node: the pixel centre
    assert np.abs(centre / image - 1).max() > 1e-6  # the averaging matters


def test_sky_band_plane_is_uniform_with_the_closed_form():
    a = analytic_scene("plane_sky_band")
    image, mask = a.exact(a.camera, 3)
    t1, t2 = (math.radians(t) for t in SKY_BAND)
    expected = (
        PLANE_ALBEDO * np.array(tuple(SKY_RADIANCE)) * (math.sin(t2) ** 2 - math.sin(t1) ** 2)
    )
    assert mask.all()
    np.testing.assert_allclose(image, np.broadcast_to(expected, image.shape), rtol=1e-12)


def test_plane_scenes_are_black_at_depth_one():
    for name in ("plane_point_light", "plane_sphere_light", "plane_sky_band"):
        a = analytic_scene(name)
        assert analytic_scene(name).exact(a.camera, 1)[0].max() == 0.0


def test_glowing_furnace_sums_the_bounces():
    a = analytic_scene("glowing_furnace")
    for depth in (1, 2, 3, 200):
        image, mask = a.exact(a.camera, depth)
        assert mask.all()
        expected = sum(GLOW_LE * GLOW_RHO**k for k in range(depth))
        np.testing.assert_allclose(image, expected, rtol=1e-14)


def test_furnace_masks_leave_out_the_outline():
    a = analytic_scene("furnace")
    cam = a.camera.with_width(32)
    sphere = a.scene.objects[0]
    on = pixels_fully_on_sphere(cam, sphere)
    off0 = pixels_fully_off_sphere(cam, sphere)
    off1 = pixels_fully_off_sphere(cam, sphere, margin=1)
    assert on.sum() > 100 and off1.sum() > 100
    assert not (on & off0).any()
    assert (off1 <= off0).all() and off1.sum() < off0.sum()  # the margin removes a ring
    _, mask = a.exact(cam, 4)
    np.testing.assert_array_equal(mask, on | off1)


def test_every_analytic_scene_builds_and_names_itself():
    for name in ANALYTIC_SCENES:
        a = analytic_scene(name)
        assert a.name == name and a.description
        assert a.camera.defocus_angle == 0.0
    with pytest.raises(KeyError, match="plane_sky_band"):
        analytic_scene("plane_sky")
