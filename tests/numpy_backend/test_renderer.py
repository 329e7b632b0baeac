"""The numpy backend of the render loop: its units of work, determinism across
workers, Ctrl-C, a material without a kernel, the `backend=` of rtpy.render and
`--backend` of the command line."""

from __future__ import annotations

import numpy as np
import pytest

import rtpy
from rtpy.cli.main import main
from rtpy.materials.material import Material
from rtpy.numpy_backend import renderer as numpy_renderer
from rtpy.numpy_backend.materials.fallback import ScalarFallback
from rtpy.numpy_backend.renderer import MAX_RAYS, NumpyBackend
from rtpy.ray import spawn_ray
from rtpy.scatter_info import ScatterInfo
from rtpy.vec3 import Color

from ..engine.test_renderer import InterruptAfter, small_scene
from .test_agreement import SEEDS, compare


def plan_units(width: int, height: int, spp: int) -> list:
    scene, camera = small_scene()
    backend = NumpyBackend(scene, camera, rtpy.RenderSettings())
    return list(backend.plan(width, height, spp).units())


@pytest.mark.parametrize("width,height,spp", [(1, 1, 1), (40, 33, 7), (100, 3, 64), (64, 64, 100)])
def test_units_cover_every_pixel_with_spp_samples_and_bounded_size(width, height, spp):
    counts = np.zeros((height, width), dtype=int)
    units = plan_units(width, height, spp)
    for unit in units:
        counts[unit.y0 : unit.y1, unit.x0 : unit.x1] += unit.spp
        assert (unit.y1 - unit.y0) * (unit.x1 - unit.x0) * unit.spp <= MAX_RAYS
    np.testing.assert_array_equal(counts, spp)
    batches = [u.batch for u in units]
    assert batches == sorted(batches)


def test_same_seed_same_image_for_any_worker_count(monkeypatch):
    monkeypatch.setattr(numpy_renderer, "MAX_RAYS", 2048)  # passes of several units
    scene, camera = small_scene()
    camera = camera.with_width(70)  # 70 x 39: 2, 2, 3, 6, 13 and 6 units a pass
    kw = dict(camera=camera, spp=20, seed=9, backend="numpy")
    one = rtpy.render(scene, workers=1, **kw)
    two = rtpy.render(scene, workers=2, **kw)
    np.testing.assert_array_equal(one.linear, two.linear)
    kw["seed"] = 10
    assert not np.array_equal(one.linear, rtpy.render(scene, **kw).linear)


def test_workers_give_the_same_image_under_every_start_method(start_method):
    """Worker processes started by fork, spawn or forkserver rebuild the numpy backend."""
    scene, camera = small_scene()
    kw = dict(camera=camera.with_width(70), spp=8, seed=3, backend="numpy")
    one = rtpy.render(scene, **kw)
    np.testing.assert_array_equal(one.linear, rtpy.render(scene, workers=2, **kw).linear)


def test_render_reports_samples_speed_and_memory():
    scene, camera = small_scene()
    image = rtpy.render(scene, camera=camera, spp=3, backend="numpy")
    assert (image.samples_min, image.samples_max, image.spp) == (3, 3, 3)
    assert image.stats["paths"] == camera.width * camera.height * 3
    assert image.stats["backend"] == "numpy"
    assert image.stats["paths_per_second"] > 0 and image.stats["peak_rss_mb"] > 0
    assert not image.interrupted and np.isfinite(image.linear).all()


def test_ctrl_c_keeps_finished_passes(monkeypatch):
    """Ctrl-C during the second pass leaves the whole first one, every pixel with a
    sample (noisier, not black in places)."""
    scene, camera = small_scene()
    camera = camera.with_width(64)  # 64 x 36
    monkeypatch.setattr(numpy_renderer, "MAX_RAYS", 64 * 36)  # a pass of 1 spp per unit
    scene.add_object(InterruptAfter(calls=64 * 36 + 100))  # during the second pass
    image = rtpy.render(scene, camera=camera, spp=2, seed=1, integrator="jittered", backend="numpy")
    assert image.interrupted
    assert image.samples_min == image.samples_max == 1
    assert image.stats["paths"] == 64 * 36
    assert (image.linear.sum(axis=2) > 0).all()


@pytest.mark.parametrize(
    "width,height,spp",
    [(256, 144, 32), (1920, 1080, 1), (3840, 2160, 1), (100000, 2, 3), (4, 2, 1)],
)
def test_units_hold_about_max_rays_paths_whatever_the_spp(width, height, spp):
    """A unit is as big as MAX_RAYS allows: every unit but the smallest of a pass holds
    more than half of MAX_RAYS paths (or the whole pass, when it holds fewer)."""
    units = plan_units(width, height, spp)
    for batch in {u.batch for u in units}:
        sizes = sorted((u.x1 - u.x0) * (u.y1 - u.y0) * u.spp for u in units if u.batch == batch)
        assert sizes[-1] <= MAX_RAYS
        assert all(size > MAX_RAYS // 2 for size in sizes[1:])


class Velvet(Material):
    """A student's material: no batched twin, so its scalar methods run per hit."""

    def __init__(self) -> None:
        self.albedo_color = Color(0.3, 0.6, 0.3)

    def scattering(self, ray_in, hit):
        from rtpy.onb import ONB
        from rtpy.sampling import random_cosine_direction

        local = random_cosine_direction()
        direction = ONB(hit.normal).to_world(local)
        z = local.z()
        ray = spawn_ray(hit.point, hit.normal, direction)
        return ScatterInfo(ray, self.albedo_color, z / np.pi)

    def BRDF(self, ray_view, ray_light, hit):
        return self.albedo_color * (1 / np.pi)

    def pdf(self, ray_view, ray_light, hit):
        n, wi = hit.normal, ray_light.direction
        return max(0.0, n.e0 * wi.e0 + n.e1 * wi.e1 + n.e2 * wi.e2) / np.pi


def test_a_material_without_a_kernel_renders_the_scalar_image(monkeypatch):
    """Velvet has no kernel, so the numpy backend calls its scalar methods per hit: its
    images agree with the scalar backend's block by block (test_agreement's z-test),
    and the test sees a fallback that weights its samples wrongly."""
    scene, camera = small_scene()
    scene.objects[0].material = Velvet()
    camera = camera.with_width(32)

    def renders(backend: str) -> list[np.ndarray]:
        kw = dict(camera=camera, spp=4, backend=backend)
        return [rtpy.render(scene, seed=seed, **kw).linear for seed in SEEDS]

    scalar = renders("scalar")
    test = compare(scalar, 4, renders("numpy"), 4)
    assert test.passed, "scalar backend: " + test.worst("the numpy backend")

    scattering = ScalarFallback.scattering

    def brighter(self, slots, hits, rng):
        out = scattering(self, slots, hits, rng)
        out.attenuation *= 1.25
        return out

    monkeypatch.setattr(ScalarFallback, "scattering", brighter)
    assert not compare(scalar, 4, renders("numpy"), 4).passed


def test_cli_backend_numpy(tmp_path, capsys):
    out = tmp_path / "c.png"
    linear = tmp_path / "c.npy"
    argv = ["render", "cornell", "--backend", "numpy", "--width", "24", "--spp", "2"]
    status = main([*argv, "-o", str(out), "--linear", str(linear), "--quiet"])
    assert status == 0 and out.exists()
    image = np.load(linear)
    assert image.shape == (24, 24, 3) and image.max() > 0
    assert "paths/s" in capsys.readouterr().err
    with pytest.raises(SystemExit) as err:
        main([*argv[:2], "--backend", "gpu"])
    assert err.value.code == 2
