"""Batched camera rays against rtpy.Camera with the same uniform numbers."""

from __future__ import annotations

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from rtpy import Camera, Vec3
from rtpy.numpy_backend.camera import CameraRays
from rtpy.sampling import use_generator


class Replay:
    """A stand-in generator whose random() returns the given numbers in order."""

    def __init__(self, values) -> None:
        self.values = list(map(float, values))

    def random(self) -> float:
        return self.values.pop(0)


def arr(v: Vec3) -> np.ndarray:
    return np.array([v.e0, v.e1, v.e2])


coord = st.floats(-50, 50, allow_nan=False)
cameras = st.builds(
    lambda lf, la, vfov, w, ar, defocus, focus: (lf, la, vfov, w, ar, defocus, focus),
    st.tuples(coord, coord, coord),
    st.tuples(coord, coord, coord),
    st.floats(5, 170),
    st.integers(1, 64),
    st.floats(0.3, 3.0),
    st.sampled_from([0.0, 0.0, 0.6, 10.0]),
    st.floats(0.5, 20),
)


def make(params) -> Camera | None:
    lf, la, vfov, w, ar, defocus, focus = params
    try:
        return Camera(Vec3(*lf), Vec3(*la), Vec3(0, 1, 0), vfov, ar, w, defocus, focus)
    except ValueError:
        return None


@settings(max_examples=150)
@given(cameras, st.data())
def test_jittered_rays_are_camera_get_ray(params, data):
    cam = make(params)
    if cam is None:
        return
    batch = CameraRays(cam)
    n = 8
    i = np.array([data.draw(st.integers(0, cam.width - 1)) for _ in range(n)])
    j = np.array([data.draw(st.integers(0, cam.height - 1)) for _ in range(n)])
    r = np.random.default_rng(len(i)).random((4, n))
    o, d = batch.rays_through(i + r[0] - 0.5, j + r[1] - 0.5, r[2], r[3])
    for k in range(n):
        draws = [r[0, k], r[1, k]] + ([r[2, k], r[3, k]] if cam.defocus_angle > 0 else [])
        with use_generator(Replay(draws)):
            ray = cam.get_ray(int(i[k]), int(j[k]))
        np.testing.assert_array_equal(o[k], arr(ray.origin))
        np.testing.assert_array_equal(d[k], arr(ray.direction))


def test_center_rays_are_camera_get_center_ray():
    cam = Camera(Vec3(1, 2, 3), Vec3(0, 0, -1), vfov=50, width=37, aspect_ratio="4:3")
    j, i = np.divmod(np.arange(cam.width * cam.height), cam.width)
    o, d = CameraRays(cam).center_rays(i, j)
    for k in range(0, len(i), 7):
        ray = cam.get_center_ray(int(i[k]), int(j[k]))
        np.testing.assert_array_equal(o[k], arr(ray.origin))
        np.testing.assert_array_equal(d[k], arr(ray.direction))


def test_jittered_rays_cover_each_pixel_uniformly():
    cam = Camera(width=4, aspect_ratio=1.0)
    batch = CameraRays(cam)
    n = 20000
    o, d = batch.jittered_rays(np.full(n, 2), np.full(n, 1), np.random.default_rng(1))
    np.testing.assert_allclose(np.linalg.norm(d, axis=1), 1.0, rtol=1e-15)
    # Back to pixel coordinates on the focus plane (z = -focus_distance = -10 here).
    p = o + d * (-10.0 / d[:, 2:3])
    px = (p[:, 0] - arr(cam.pixel00)[0]) / arr(cam.pixel_delta_u)[0]
    assert np.all((px > 1.5) & (px < 2.5))
    assert abs(px.mean() - 2.0) < 4 * (1 / np.sqrt(12)) / np.sqrt(n)
