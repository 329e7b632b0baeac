"""rtpy.engine.scalar_backend: a unit of work ray by ray, each unit's numbers from its own
generator (so a unit gives the same sums wherever and whenever it is rendered)."""

from __future__ import annotations

import numpy as np

import rtpy
from rtpy.engine.plan import Unit
from rtpy.engine.scalar_backend import ScalarBackend, render_unit

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
