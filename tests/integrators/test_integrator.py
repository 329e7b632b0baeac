"""The Integrator base class, the registry of integrators by scene name, and what every
integrator that lights a scene must get right: the furnace tests, whose answers are
known in closed form."""

from __future__ import annotations

import numpy as np
import pytest

import rtpy
from rtpy import Color, Dielectric, Lambertian, Ray, RenderSettings, Scene, Vec3
from rtpy.integrators import INTEGRATORS, Integrator, make_integrator
from rtpy.testing.analytic_scenes import (
    furnace_scene,
    pixels_fully_off_sphere,
    pixels_fully_on_sphere,
)


def test_every_integrator_is_registered_by_its_scene_name():
    assert set(INTEGRATORS) == {"center", "jittered", "shading", "direct", "whitted", "path"}
    for name, cls in INTEGRATORS.items():
        assert cls.name == name
        integrator = make_integrator(RenderSettings(integrator=name, max_depth=3))
        assert type(integrator) is cls and integrator.settings.max_depth == 3


def test_the_base_class_has_default_settings_and_no_estimate():
    integrator = Integrator()
    assert integrator.settings == RenderSettings()
    assert integrator.uses_center_ray is False
    with pytest.raises(NotImplementedError):
        integrator.compute_scattering(Ray(Vec3(0, 0, 0), Vec3(0, 0, -1)), Scene([]))


def test_radiance_is_compute_scattering_under_its_meaning():
    """Overriding the course's name is enough: radiance() calls it."""

    class Constant(Integrator):
        def compute_scattering(self, ray, scene):
            return Color(0.25, 0.5, 1.0)

    ray = Ray(Vec3(0, 0, 0), Vec3(0, 0, -1))
    assert Constant().radiance(ray, Scene([])) == Color(0.25, 0.5, 1.0)


@pytest.mark.parametrize(
    "integrator,nee", [("direct", True), ("path", True), ("path", False), ("whitted", True)]
)
def test_furnace_convex_lambertian_sphere_shows_its_albedo(integrator, nee):
    """A convex object never sees itself: lit by a uniform environment of radiance 1
    its radiance is exactly its albedo, whatever direction a bounce takes (so every
    sample is exact, no noise). A missing 1/pdf or cosine would scale it."""
    a = 0.7
    scene, camera = furnace_scene(Lambertian(Color(a, 0.5 * a, 0.25)))
    image = rtpy.render(scene, camera=camera, integrator=integrator, nee=nee, spp=4, max_depth=6)
    sphere = scene.objects[0]
    on, off = pixels_fully_on_sphere(camera, sphere), pixels_fully_off_sphere(camera, sphere)
    assert on.sum() > 50 and off.sum() > 50
    np.testing.assert_allclose(
        image.linear[on], np.broadcast_to([a, 0.5 * a, 0.25], (on.sum(), 3)), rtol=1e-12
    )
    np.testing.assert_array_equal(image.linear[off], 1.0)


@pytest.mark.parametrize("integrator", ["path", "whitted"])
def test_furnace_glass_sphere_conserves_energy(integrator):
    """Clear glass (albedo 1) in a white furnace neither adds nor loses light:
    every pixel is 1, up to the energy still trapped inside after max_depth."""
    scene, camera = furnace_scene(Dielectric(1.5))
    image = rtpy.render(scene, camera=camera, integrator=integrator, spp=4, max_depth=40)
    np.testing.assert_allclose(image.linear, 1.0, atol=1e-6)
