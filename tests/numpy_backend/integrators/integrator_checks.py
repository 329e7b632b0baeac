"""Shared helpers of the integrator tests: camera rays, the scalar and the batched
radiance of the same rays, a z-score, a deterministic test scene."""

from __future__ import annotations

import math

import numpy as np

import rtpy
from rtpy import Color, Dielectric, Lambertian, Mirror, PointLight, Scene, Sphere, Vec3
from rtpy.integrators import make_integrator as make_scalar
from rtpy.numpy_backend.camera import CameraRays
from rtpy.numpy_backend.integrators import make_integrator
from rtpy.numpy_backend.scene import BatchScene
from rtpy.ray import Ray
from rtpy.render_settings import RenderSettings
from rtpy.sampling import make_generator, use_generator


def camera_rays(camera, width=24, stride=1):
    cam = camera.with_width(width)
    j, i = np.divmod(np.arange(cam.width * cam.height)[::stride], cam.width)
    return CameraRays(cam).center_rays(i, j)


def scalar_radiance(scene, settings, o, d):
    integrator = make_scalar(settings)
    out = np.empty((len(o), 3))
    with use_generator(make_generator(1)):
        for k in range(len(o)):
            c = integrator.compute_scattering(Ray(Vec3(*o[k]), Vec3(*d[k])), scene)
            out[k] = (c.e0, c.e1, c.e2)
    return out


def batched_radiance(scene, settings, o, d, seed=0):
    return make_integrator(settings).compute_scattering(
        o, d, BatchScene(scene), np.random.default_rng(seed)
    )


def point_light_scene() -> Scene:
    """Lambertian, mirror and glass under two point lights and a black sky: direct
    and Whitted are deterministic here (BRDF-sampled rays only see black)."""
    return Scene(
        [
            Sphere(Vec3(0, -100.5, -1), 100, Lambertian(Color(0.7, 0.6, 0.5))),
            Sphere(Vec3(-1, 0, -1), 0.5, Lambertian(Color(0.2, 0.3, 0.8))),
            Sphere(Vec3(0, 0, -1.2), 0.5, Mirror(Color(0.9, 0.9, 0.8))),
            Sphere(Vec3(1, 0, -1), 0.5, Dielectric(1.5)),
        ],
        point_lights=[
            PointLight(Vec3(1, 3, 1), Color(5, 5, 5)),
            PointLight(Vec3(-2, 2, 0), Color(2, 1, 1)),
        ],
        camera=rtpy.Camera(Vec3(0, 0.5, 1.5), Vec3(0, 0, -1), vfov=70),
    )


def z_score(samples: np.ndarray, expected) -> np.ndarray:
    mean = samples.mean(axis=0)
    se = samples.std(axis=0, ddof=1) / math.sqrt(len(samples))
    return np.abs(mean - expected) / np.maximum(se, 1e-12)


def check_ray_by_ray(integrator: str) -> None:
    """In point_light_scene, where BRDF-sampled rays see only black, the integrator is
    deterministic given the light: the batched radiance equals the scalar one, ray by
    ray, with each light made the only one in turn (the light choice is random)."""
    scene = point_light_scene()
    o, d = camera_rays(scene.camera, 40, stride=2)
    settings = RenderSettings(integrator=integrator, max_depth=6)
    for light in list(scene.point_lights):
        scene.point_lights = [light]
        scene.update_lights()
        got = batched_radiance(scene, settings, o, d)
        ref = scalar_radiance(scene, settings, o, d)
        np.testing.assert_allclose(got, ref, rtol=1e-9, atol=1e-12)
