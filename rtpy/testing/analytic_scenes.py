"""Scenes whose exact image is known in closed form, for tests and `rtpy bench`.

Each AnalyticScene holds a scene built through the Python API, its camera, the
render settings it is meant for, and `exact(camera, max_depth)`: the exact pixel
values (linear radiance, the expectation of any unbiased estimator at that
max_depth) and the mask of pixels where they are exact. A pixel's value is the
average of the radiance over the pixel's square (the box filter of the
renderers); where it varies inside a pixel, that average is taken by a Gauss-
Legendre rule of FOOTPRINT_ORDER^2 nodes on the exact, smooth integrand.

- furnace: a convex Lambertian sphere in a uniform white environment shows its
  albedo exactly, at every sample (no noise): a wrong 1/pdf or cosine scales it.
- glowing_furnace: the camera inside a closed sphere of albedo rho that also
  emits Le: L = Le (1 + rho + ... + rho^(D-1)) for D = max_depth segments
  (Le / (1 - rho) as D grows); the sphere is an area light sampled from inside.
- plane_point_light: a Lambertian plane under a point light:
  L = albedo / pi * I cos(theta) / d^2.
- plane_sphere_light: the same plane under a sphere light of radiance Le and
  radius r whose centre is at distance d, higher than r above the plane (so it
  is wholly above every point's horizon): E = pi Le (r / d)^2 cos(theta),
  L = albedo / pi * E. Light sampling, BRDF sampling and MIS all reach it.
- plane_sky_band: the plane under a sky bright (radiance Ls) only between the
  zenith angles theta1 and theta2: E = Ls pi (sin^2 theta2 - sin^2 theta1), the
  same at every point, L = albedo / pi * E. The band (60 to 85 degrees) is
  near the horizon, where a wrong cosine or pdf weighting shows most.

In the plane scenes the camera sees only the plane, and the plane does not see
itself, so every max_depth >= 2 gives the same image (max_depth 1: black).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from dataclasses import dataclass

import numpy as np

from ..camera import Camera
from ..environment import SkyBand
from ..light import PointLight
from ..materials import DiffuseLight, Lambertian
from ..quad import Quad
from ..render_settings import RenderSettings
from ..scene import Scene
from ..sphere import Sphere
from ..vec3 import Color, Vec3

FOOTPRINT_ORDER = 8  # Gauss-Legendre nodes per pixel side for pixel averages

# (image (H, W, 3), mask (H, W)) for a camera and a max_depth
ExactImage = Callable[[Camera, int], tuple[np.ndarray, np.ndarray]]


@dataclass
class AnalyticScene:
    """A scene, its camera and settings, and its exact image. ray_radiance, where
    given, is the exact radiance along camera rays (origins (N, 3), unit
    directions (N, 3)) -> (N, 3) for max_depth >= 2, which exact() averages over
    each pixel."""

    name: str
    description: str
    scene: Scene
    camera: Camera
    settings: RenderSettings
    exact: ExactImage
    ray_radiance: Callable[[np.ndarray, np.ndarray], np.ndarray] | None = None


# --------------------------------------------------------------------------- helpers


def _rgb(c: Color) -> np.ndarray:
    return np.array([c.e0, c.e1, c.e2])


def _vec(v: Vec3) -> np.ndarray:
    return np.array([v.e0, v.e1, v.e2])


def pixel_average(camera: Camera, radiance, order: int = FOOTPRINT_ORDER) -> np.ndarray:
    """(H, W, 3): the average over each pixel's square of radiance(origins, directions)
    -> (N, 3), by an order x order Gauss-Legendre rule (pinhole cameras only)."""
    if camera.defocus_angle > 0.0:
        raise ValueError("pixel_average needs a pinhole camera (defocus_angle = 0)")
    nodes, weights = np.polynomial.legendre.leggauss(order)
    nodes, weights = 0.5 * nodes, 0.5 * weights  # on [-1/2, 1/2], summing to 1
    j, i = np.mgrid[0 : camera.height, 0 : camera.width]
    shape = (camera.height, camera.width, order, order)  # (H, W, node x, node y)
    px = np.broadcast_to(i[..., None, None] + nodes[:, None], shape).ravel()
    py = np.broadcast_to(j[..., None, None] + nodes[None, :], shape).ravel()
    p00, du, dv = _vec(camera.pixel00), _vec(camera.pixel_delta_u), _vec(camera.pixel_delta_v)
    origin = _vec(camera.look_from)
    d = p00 + px[:, None] * du + py[:, None] * dv - origin
    d /= np.linalg.norm(d, axis=1, keepdims=True)
    values = radiance(np.broadcast_to(origin, d.shape), d)
    values = values.reshape(camera.height, camera.width, order, order, 3)
    w2 = weights[:, None] * weights[None, :]
    return np.einsum("hwxyc,xy->hwc", values, w2)


def _pixel_corner_rays_hit(camera: Camera, sphere: Sphere) -> np.ndarray:
    """(H + 1, W + 1): whether the ray through each pixel corner hits the sphere."""
    hits = np.zeros((camera.height + 1, camera.width + 1), dtype=bool)
    for j in range(camera.height + 1):
        for i in range(camera.width + 1):
            ray = camera._ray_through(i - 0.5, j - 0.5)
            hits[j, i] = sphere.hit_t(ray, 0.0, math.inf) is not None
    return hits


def pixels_fully_on_sphere(camera: Camera, sphere: Sphere) -> np.ndarray:
    """Mask (H, W) of pixels whose whole square sees the sphere: its 4 corners hit,
    and the sphere's image is convex."""
    c = _pixel_corner_rays_hit(camera, sphere)
    return c[:-1, :-1] & c[1:, :-1] & c[:-1, 1:] & c[1:, 1:]


def pixels_fully_off_sphere(camera: Camera, sphere: Sphere, margin: int = 0) -> np.ndarray:
    """Mask (H, W) of pixels none of whose corners sees the sphere, nor those of the
    pixels up to `margin` pixels away (a margin of 1 keeps out pixels that the
    sphere's outline might enter between two corners)."""
    c = _pixel_corner_rays_hit(camera, sphere)
    touched = c[:-1, :-1] | c[1:, :-1] | c[:-1, 1:] | c[1:, 1:]
    for _ in range(margin):
        grown = touched.copy()
        grown[1:, :] |= touched[:-1, :]
        grown[:-1, :] |= touched[1:, :]
        grown[:, 1:] |= touched[:, :-1]
        grown[:, :-1] |= touched[:, 1:]
        grown[1:, 1:] |= touched[:-1, :-1]
        grown[:-1, :-1] |= touched[1:, 1:]
        grown[1:, :-1] |= touched[:-1, 1:]
        grown[:-1, 1:] |= touched[1:, :-1]
        touched = grown
    return ~touched


class GlowingLambertian(Lambertian):
    """Diffuse reflection plus uniform emission `emit` from both faces."""

    is_emitter = True

    def __init__(self, albedo: Color, emit: Color) -> None:
        super().__init__(albedo)
        self.emit = emit

    def emitting(self, hit):
        return self.emit


# --------------------------------------------------------------------------- scenes


def furnace_scene(material) -> tuple[Scene, Camera]:
    """A unit sphere of `material` at distance 3 in front of the camera, in a uniform
    environment of radiance 1."""
    scene = Scene([Sphere(Vec3(0, 0, -3), 1.0, material)], background=Color(1.0, 1.0, 1.0))
    camera = Camera(Vec3(0, 0, 0), Vec3(0, 0, -3), vfov=50, aspect_ratio=1.0, width=24)
    return scene, camera


FURNACE_ALBEDO = Color(0.7, 0.35, 0.25)


def furnace() -> AnalyticScene:
    scene, camera = furnace_scene(Lambertian(FURNACE_ALBEDO))
    sphere = scene.objects[0]

    def exact(cam: Camera, max_depth: int):
        on = pixels_fully_on_sphere(cam, sphere)
        off = pixels_fully_off_sphere(cam, sphere, margin=1)
        image = np.ones((cam.height, cam.width, 3))
        image[on] = _rgb(FURNACE_ALBEDO) if max_depth >= 2 else 0.0
        return image, on | off

    return AnalyticScene(
        "furnace",
        "convex Lambertian sphere in a white environment: its albedo, noise-free",
        scene,
        camera,
        RenderSettings(max_depth=6),
        exact,
    )


GLOW_RHO, GLOW_LE = 0.5, 0.5


def glowing_furnace() -> AnalyticScene:
    rho, le = GLOW_RHO, GLOW_LE
    material = GlowingLambertian(Color(rho, rho, rho), Color(le, le, le))
    scene = Scene([Sphere(Vec3(0, 0, 0), 2.0, material)])
    camera = Camera(Vec3(0.3, -0.2, 0.1), Vec3(0, 0, -1), vfov=100, aspect_ratio=1.0, width=12)

    def exact(cam: Camera, max_depth: int):
        value = le * (1.0 - rho**max_depth) / (1.0 - rho)
        return np.full((cam.height, cam.width, 3), value), np.ones(
            (cam.height, cam.width), dtype=bool
        )

    return AnalyticScene(
        "glowing_furnace",
        "inside a sphere of albedo 0.5 emitting 0.5: L = 1 (Le / (1 - rho))",
        scene,
        camera,
        RenderSettings(max_depth=200, russian_roulette=3),
        exact,
    )


PLANE_ALBEDO = 0.6


def _plane_and_camera() -> tuple[Quad, Camera]:
    """A large Lambertian plane y = 0 (its quad normal points down; Lambertian is
    two-sided) and a camera that sees nothing else (its top rows look 10 degrees
    below the horizon)."""
    a = PLANE_ALBEDO
    plane = Quad(Vec3(-60, 0, -60), Vec3(120, 0, 0), Vec3(0, 0, 120), Lambertian(Color(a, a, a)))
    camera = Camera(Vec3(0, 3, 2), Vec3(0, 0, -1), vfov=70, aspect_ratio=1.5, width=30)
    return plane, camera


def _plane_hits(o: np.ndarray, d: np.ndarray) -> np.ndarray:
    """Points where rays from above meet the plane y = 0."""
    t = -o[:, 1] / d[:, 1]
    return o + t[:, None] * d


def _plane_scene(name: str, description: str, scene: Scene, camera: Camera, radiance_at):
    """A plane scene whose radiance at plane points p (N, 3) is radiance_at(p) (N, 3)
    for max_depth >= 2 (and 0 for max_depth 1)."""

    def ray_radiance(o: np.ndarray, d: np.ndarray) -> np.ndarray:
        return radiance_at(_plane_hits(o, d))

    def exact(cam: Camera, max_depth: int):
        mask = np.ones((cam.height, cam.width), dtype=bool)
        if max_depth < 2:
            return np.zeros((cam.height, cam.width, 3)), mask
        return pixel_average(cam, ray_radiance), mask

    return AnalyticScene(
        name, description, scene, camera, RenderSettings(max_depth=4), exact, ray_radiance
    )


POINT_LIGHT_POSITION = Vec3(0.3, 2.0, -0.5)
POINT_LIGHT_INTENSITY = Color(5.0, 2.5, 1.0)


def plane_point_light() -> AnalyticScene:
    plane, camera = _plane_and_camera()
    light = PointLight(POINT_LIGHT_POSITION, POINT_LIGHT_INTENSITY)
    scene = Scene([plane], [light])
    pos, intensity = _vec(POINT_LIGHT_POSITION), _rgb(POINT_LIGHT_INTENSITY)

    def radiance_at(p: np.ndarray) -> np.ndarray:
        to_light = pos - p
        d2 = np.einsum("ij,ij->i", to_light, to_light)
        cos_theta = to_light[:, 1] / np.sqrt(d2)
        return (PLANE_ALBEDO / math.pi) * (cos_theta / d2)[:, None] * intensity

    return _plane_scene(
        "plane_point_light",
        "Lambertian plane under a point light: albedo/pi I cos(theta)/d^2 per pixel",
        scene,
        camera,
        radiance_at,
    )


SPHERE_LIGHT_CENTER = Vec3(0.5, 2.0, 3.0)  # behind the camera: not in view
SPHERE_LIGHT_RADIUS = 0.8
SPHERE_LIGHT_RADIANCE = Color(4.0, 3.0, 2.0)


def plane_sphere_light() -> AnalyticScene:
    plane, camera = _plane_and_camera()
    light = Sphere(SPHERE_LIGHT_CENTER, SPHERE_LIGHT_RADIUS, DiffuseLight(SPHERE_LIGHT_RADIANCE))
    scene = Scene([plane, light])
    center, le, r = _vec(SPHERE_LIGHT_CENTER), _rgb(SPHERE_LIGHT_RADIANCE), SPHERE_LIGHT_RADIUS
    assert center[1] > r  # wholly above every point's horizon

    def radiance_at(p: np.ndarray) -> np.ndarray:
        to_light = center - p
        d = np.sqrt(np.einsum("ij,ij->i", to_light, to_light))
        cos_theta = to_light[:, 1] / d
        # albedo / pi * (pi Le (r / d)^2 cos(theta))
        return PLANE_ALBEDO * ((r / d) ** 2 * cos_theta)[:, None] * le

    return _plane_scene(
        "plane_sphere_light",
        "Lambertian plane under a sphere light: albedo Le (r/d)^2 cos(theta) per pixel",
        scene,
        camera,
        radiance_at,
    )


SKY_BAND = (60.0, 85.0)  # zenith angles, degrees
SKY_RADIANCE = Color(2.0, 1.5, 1.0)


def plane_sky_band() -> AnalyticScene:
    plane, camera = _plane_and_camera()
    sky = SkyBand(SKY_RADIANCE, *SKY_BAND)
    scene = Scene([plane], environment=sky)
    value = _rgb(sky.irradiance_up()) * (PLANE_ALBEDO / math.pi)

    return _plane_scene(
        "plane_sky_band",
        "Lambertian plane under a sky bright 60-85 deg from the zenith: "
        "albedo Ls (sin^2 t2 - sin^2 t1)",
        scene,
        camera,
        lambda p: np.broadcast_to(value, p.shape),
    )


ANALYTIC_SCENES: dict[str, Callable[[], AnalyticScene]] = {
    "furnace": furnace,
    "glowing_furnace": glowing_furnace,
    "plane_point_light": plane_point_light,
    "plane_sphere_light": plane_sphere_light,
    "plane_sky_band": plane_sky_band,
}


def analytic_scene(name: str) -> AnalyticScene:
    """The analytic scene of that name (a KeyError names the valid ones)."""
    try:
        return ANALYTIC_SCENES[name]()
    except KeyError:
        raise KeyError(f"no analytic scene {name!r}; known: {', '.join(ANALYTIC_SCENES)}") from None
