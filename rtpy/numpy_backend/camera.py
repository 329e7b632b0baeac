"""Batched camera rays: the twin of rtpy/camera.py for many pixel samples at once.

Pixel (i, j) is column i, row j, (0, 0) the top-left. A jittered sample is
uniform over the pixel's square; a center ray goes through its center. With a
defocus angle the origin is uniform on the thin lens's disk. Directions are
unit vectors. The arithmetic is Camera._ray_through's, component by component,
so the same uniform numbers give the same rays to the last bit.
"""

from __future__ import annotations

import numpy as np

from ..camera import Camera
from .arrays import scale
from .sampling import unit_disk


def _v(v) -> np.ndarray:
    return np.array([v.e0, v.e1, v.e2], dtype=np.float64)


class CameraRays:
    """Makes (origins (N, 3), directions (N, 3)) for pixel samples of a Camera."""

    def __init__(self, camera: Camera) -> None:
        self.camera = camera
        self.width, self.height = camera.width, camera.height
        self.pixel00 = _v(camera.pixel00)
        self.du = _v(camera.pixel_delta_u)
        self.dv = _v(camera.pixel_delta_v)
        self.look_from = _v(camera.look_from)
        self.defocus = camera.defocus_angle > 0.0
        self.disk_u = _v(camera.defocus_disk_u)
        self.disk_v = _v(camera.defocus_disk_v)

    def rays_through(
        self,
        px: np.ndarray,
        py: np.ndarray,
        lens1: np.ndarray | None = None,
        lens2: np.ndarray | None = None,
    ) -> tuple[np.ndarray, np.ndarray]:
        """Rays through fractional pixel positions (px, py); with defocus, lens1 and
        lens2 are the two uniform numbers random_in_unit_disk would draw."""
        # Component by component (a (3,) row broadcast against (N, 1) columns is
        # several times slower in numpy), in the scalar code's order of operations.
        n = len(px)
        target, origin = np.empty((n, 3)), np.empty((n, 3))
        if self.defocus:
            x, y = unit_disk(lens1, lens2)
        for c in range(3):
            col = target[:, c]
            np.multiply(px, self.du[c], out=col)
            col += self.pixel00[c]
            col += py * self.dv[c]
            if self.defocus:
                origin[:, c] = (self.look_from[c] + self.disk_u[c] * x) + self.disk_v[c] * y
            else:
                origin[:, c] = self.look_from[c]
        d = target - origin
        k = 1.0 / np.sqrt(d[:, 0] * d[:, 0] + d[:, 1] * d[:, 1] + d[:, 2] * d[:, 2])
        return origin, scale(d, k)

    def center_rays(self, i: np.ndarray, j: np.ndarray, rng=None):
        """Camera.get_center_ray for pixels (i, j); the lens still needs uniforms."""
        lens = self._lens(len(i), rng)
        return self.rays_through(i.astype(np.float64), j.astype(np.float64), *lens)

    def jittered_rays(self, i: np.ndarray, j: np.ndarray, rng: np.random.Generator):
        """Camera.get_ray for pixels (i, j): uniform in each pixel's square."""
        n = len(i)
        r = rng.random((2, n))
        px = i + r[0] - 0.5
        py = j + r[1] - 0.5
        return self.rays_through(px, py, *self._lens(n, rng))

    def _lens(self, n: int, rng):
        if not self.defocus:
            return None, None
        if rng is None:
            rng = np.random.default_rng(0)
        r = rng.random((2, n))
        return r[0], r[1]
