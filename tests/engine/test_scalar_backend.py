"""rtpy.engine.scalar_backend: a unit of work ray by ray, each unit's numbers from its own
generator (so a unit gives the same sums wherever and whenever it is rendered)."""

from __future__ import annotations

import numpy as np

import rtpy
from rtpy.engine.plan import Unit
from rtpy.engine.scalar_backend import ScalarBackend, render_unit
from rtpy.sampler import SAMPLERS
from rtpy.sampling import make_generator, use_generator

from .test_renderer import small_scene


def test_a_unit_is_the_sum_of_its_samples_the_same_wherever_it_runs():
    scene, camera = small_scene()
    backend = ScalarBackend(scene, camera, rtpy.RenderSettings(spp=4, seed=2))
    render_one = backend.start()
    unit = Unit(3, 2, 5, 4, 13, 9, 2, 2)  # region 3 of pass 2: 8 x 5 pixels, 2 spp
    sums = render_one(unit)
    assert sums.shape == (5, 8, 3) and np.isfinite(sums).all() and (sums >= 0).all()
    np.testing.assert_array_equal(
        ScalarBackend(scene, camera, backend.settings).start()(unit), sums
    )
    other_pass = Unit(3, 3, 5, 4, 13, 9, 2, 2)
    assert not np.array_equal(render_one(other_pass), sums)


def test_one_sample_per_pixel_is_the_integrators_radiance():
    scene, camera = small_scene()
    settings = rtpy.RenderSettings(integrator="center")
    integrator = ScalarBackend(scene, camera, settings).make_integrator()
    sums = render_unit(scene, camera, integrator, 0, Unit(0, 0, 10, 10, 12, 11, 1))
    for j, i in [(10, 10), (10, 11)]:
        c = integrator.compute_scattering(camera.get_center_ray(i, j), scene)
        np.testing.assert_array_equal(sums[j - 10, i - 10], [c.e0, c.e1, c.e2])


def test_a_sampler_is_told_each_pixel_and_sample_index():
    """With a sampler, pixel (i, j)'s sample k is sample k of pixel j * width + i: the
    sums are those of paths traced after start_pixel_sample(that pixel, k)."""
    scene, camera = small_scene()
    settings = rtpy.RenderSettings(spp=4, seed=3, sampler="stratified")
    integrator = ScalarBackend(scene, camera, settings).make_integrator()
    unit = Unit(0, 1, 6, 3, 9, 5, 2, 2)  # 3 x 2 pixels, samples 2 and 3
    sums = render_unit(scene, camera, integrator, 3, unit, sampler="stratified")
    sampler = SAMPLERS["stratified"](3, 4, False, fallback=make_generator(3, 0, 1))
    expected = np.zeros((2, 3, 3))
    with use_generator(sampler):
        for j in range(3, 5):
            for i in range(6, 9):
                for k in (2, 3):
                    sampler.start_pixel_sample(j * camera.width + i, k)
                    c = integrator.compute_scattering(camera.get_ray(i, j), scene)
                    expected[j - 3, i - 6] += [c.e0, c.e1, c.e2]
    np.testing.assert_array_equal(sums, expected)
