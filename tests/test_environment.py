"""Environments (radiance by direction): SkyBand's closed form, and both backends
seeing the same environment."""

from __future__ import annotations

import math

import numpy as np
import pytest

from rtpy import Color, Scene, Vec3
from rtpy.environment import Environment, SkyBand
from rtpy.numpy_backend.scene import BatchScene


def random_directions(n: int, seed: int = 0) -> np.ndarray:
    d = np.random.default_rng(seed).normal(size=(n, 3))
    return d * np.random.default_rng(seed + 1).uniform(0.5, 2.0, size=(n, 1))  # not unit


@pytest.mark.parametrize("band", [(0.0, 30.0), (60.0, 85.0), (10.0, 90.0), (45.0, 120.0)])
def test_sky_band_irradiance_is_the_integral_of_radiance_times_cosine(band):
    """E = integral over the upper hemisphere of L(theta) cos(theta) dw, by a fine
    midpoint rule in theta (the band's edges fall between nodes at most once each)."""
    sky = SkyBand(Color(2.0, 1.0, 0.5), *band)
    n = 200_000
    theta = (np.arange(n) + 0.5) * (math.pi / 2) / n
    d = np.stack([np.sin(theta), np.cos(theta), np.zeros(n)], axis=1)
    L = sky.radiance_array(d)[:, 0]
    numeric = (L * np.cos(theta) * np.sin(theta)).sum() * (math.pi / 2) / n * 2 * math.pi
    assert sky.irradiance_up().e0 == pytest.approx(numeric, rel=1e-4)
    assert sky.irradiance_up().e1 == pytest.approx(sky.irradiance_up().e0 / 2)


def test_sky_band_scalar_and_array_agree_and_only_the_band_is_bright():
    sky = SkyBand(Color(1.0, 2.0, 3.0), 60.0, 85.0)
    d = random_directions(2000)
    arr = sky.radiance_array(d)
    scalar = np.array([tuple(sky.radiance(Vec3(*row))) for row in d])
    np.testing.assert_array_equal(arr, scalar)
    theta = np.degrees(np.arccos(d[:, 1] / np.linalg.norm(d, axis=1)))
    bright = arr[:, 0] > 0
    assert bright.any() and (~bright).any()
    assert np.all((theta[bright] >= 60.0 - 1e-9) & (theta[bright] <= 85.0 + 1e-9))
    assert np.all((theta[~bright] < 60.0) | (theta[~bright] > 85.0))


@pytest.mark.parametrize("band", [(30.0, 30.0), (-1.0, 20.0), (10.0, 181.0)])
def test_sky_band_refuses_bad_angles(band):
    with pytest.raises(ValueError, match="^theta_m(in|ax): "):
        SkyBand(Color(1, 1, 1), *band)


class Gradient(Environment):
    """An environment with only the scalar method: the numpy backend calls it per row."""

    def radiance(self, direction):
        y = direction.e1 / direction.length()
        return Color(1.0 + y, 0.5, 0.0)


@pytest.mark.parametrize("env", [SkyBand(Color(1.0, 2.0, 3.0), 20.0, 70.0), Gradient()])
def test_both_backends_see_the_scene_environment(env):
    """Scene.environment replaces background and sky, in both backends alike."""
    scene = Scene([], background=Color(9.0, 9.0, 9.0), sky=True, environment=env)
    d = random_directions(300, seed=4)
    batched = BatchScene(scene).background_radiance(d)
    scalar = np.array([tuple(scene.background_radiance(Vec3(*row))) for row in d])
    np.testing.assert_allclose(batched, scalar, rtol=1e-15)
    assert not np.any(batched == 9.0)
