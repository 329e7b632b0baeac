"""Renderer: work units, determinism across worker counts, interrupted renders."""

from __future__ import annotations

import numpy as np
import pytest

import rtpy
from rtpy import Camera, Color, DiffuseLight, Lambertian, Metal, Scene, Sphere, Vec3
from rtpy.renderer import plan_units


@pytest.mark.parametrize("width,height,spp", [(1, 1, 1), (16, 16, 16), (37, 21, 5), (40, 3, 64)])
def test_units_cover_every_pixel_with_exactly_spp_samples(width, height, spp):
    counts = np.zeros((height, width), dtype=int)
    for unit in plan_units(width, height, spp):
        counts[unit.y0 : unit.y1, unit.x0 : unit.x1] += unit.spp
    np.testing.assert_array_equal(counts, spp)


def test_units_run_batch_by_batch():
    """Every tile gets its first batch before any tile gets a second one, so an
    interrupted render covers the whole image."""
    batches = [u.batch for u in plan_units(64, 48, 16)]
    assert batches == sorted(batches)


def small_scene() -> tuple[Scene, Camera]:
    scene = Scene(
        [
            Sphere(Vec3(0, -100.5, -1), 100, Lambertian(Color(0.5, 0.5, 0.5))),
            Sphere(Vec3(0, 0, -1), 0.5, Metal(Color(0.8, 0.6, 0.2), 0.3)),
            Sphere(Vec3(0, 1.5, -1), 0.3, DiffuseLight(Color(4, 4, 4))),
        ],
        sky=True,
    )
    return scene, Camera(Vec3(0, 0.3, 1), Vec3(0, 0, -1), vfov=60, width=40)


def test_same_seed_same_image_for_any_worker_count():
    scene, camera = small_scene()
    one = rtpy.render(scene, camera=camera, spp=4, seed=9, workers=1)
    two = rtpy.render(scene, camera=camera, spp=4, seed=9, workers=2)
    np.testing.assert_array_equal(one.linear, two.linear)
    other_seed = rtpy.render(scene, camera=camera, spp=4, seed=10, workers=1)
    assert not np.array_equal(one.linear, other_seed.linear)


def test_render_reports_samples_and_speed():
    scene, camera = small_scene()
    image = rtpy.render(scene, camera=camera, spp=3)
    assert (image.samples_min, image.samples_max, image.spp) == (3, 3, 3)
    assert image.stats["paths"] == camera.width * camera.height * 3
    assert image.stats["paths_per_second"] > 0
    assert not image.interrupted


class InterruptAfter(Sphere):
    """A sphere that simulates Ctrl-C after a number of intersection tests."""

    def __init__(self, calls: int) -> None:
        super().__init__(Vec3(0, 0, -50), 1.0, Lambertian())
        self.calls = calls

    def hit_t(self, ray, t_min, t_max):
        self.calls -= 1
        if self.calls == 0:
            raise KeyboardInterrupt
        return super().hit_t(ray, t_min, t_max)


def test_ctrl_c_keeps_finished_samples():
    scene, camera = small_scene()
    pixels = camera.width * camera.height
    scene.add(InterruptAfter(calls=pixels * 8))  # about a quarter of the work
    image = rtpy.render(scene, camera=camera, spp=8, seed=1)
    assert image.interrupted
    assert 1 <= image.samples_min < 8
    assert image.samples_max < 8
    assert image.stats["paths"] < pixels * 8
    # Every pixel holds some finished samples: no black holes in the image.
    assert (image.linear.sum(axis=2) > 0).all()
    assert np.isfinite(image.linear).all()
