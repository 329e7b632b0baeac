"""Camera: a pinhole or thin-lens camera that makes one ray per pixel sample.

Image coordinates: pixel (i, j) is column i (left to right) and row j (top to
bottom); pixel (0, 0) is the top-left. World: right-handed, y up. Angles are
degrees. Rays leave the camera with unit directions.
"""

from __future__ import annotations

import math

from ._checks import (
    ASPECT_RATIO,
    DEFOCUS_ANGLE,
    LENGTH,
    MIN_SINE,
    VFOV,
    checked_edge,
    checked_number,
    checked_point,
)
from .ray import Ray
from .render_settings import SETTINGS
from .sampling import generator, random_in_unit_disk
from .vec3 import Vec3, cross, unit_vector

# The most pixels an image may have. A render keeps about 60 bytes per pixel (sums,
# sample counts, the linear image) and 8-bit output another 30, so 2^25 pixels
# (8K UHD, 7680 x 4320, fits) need about 3 GB; larger images are refused before
# anything is allocated.
MAX_PIXELS = 1 << 25


def parse_aspect_ratio(value: float | str) -> float:
    """16/9 from 1.777..., "16:9" or "16/9"."""
    if isinstance(value, str):
        for sep in (":", "/"):
            if sep in value:
                a, b = (float(part) for part in value.split(sep, 1))
                if not b > 0.0:
                    raise ValueError(f"aspect ratio {value!r} divides by {b}")
                return a / b
        return float(value)
    return float(value)


class Camera:
    """Thin-lens camera (RTIOW's model).

    look_from, look_at, vup  eye, target and up hint (world units)
    vfov                     vertical field of view in degrees
    aspect_ratio             width / height (number or "16:9")
    width                    image width in pixels; height = max(1, int(width / aspect_ratio))
    defocus_angle            cone angle (degrees) of rays through a pixel; 0 = pinhole
    focus_distance           distance from look_from to the plane in perfect focus
    """

    def __init__(
        self,
        look_from: Vec3 = Vec3(0.0, 0.0, 0.0),
        look_at: Vec3 = Vec3(0.0, 0.0, -1.0),
        vup: Vec3 = Vec3(0.0, 1.0, 0.0),
        vfov: float = 90.0,
        aspect_ratio: float | str = 16.0 / 9.0,
        width: int = 400,
        defocus_angle: float = 0.0,
        focus_distance: float = 10.0,
    ) -> None:
        # Checked first (the names of wrong parameters in the errors), then RTIOW's camera.
        checked = checked_parameters(
            look_from, look_at, vup, vfov, aspect_ratio, width, defocus_angle, focus_distance
        )
        self.look_from, self.look_at, self.vup, self.vfov = checked[:4]
        self.aspect_ratio, self.width, self.defocus_angle, self.focus_distance = checked[4:]
        self.height = max(1, int(self.width / self.aspect_ratio))

        self.w = unit_vector(self.look_from - self.look_at)  # backward, away from the scene
        self.u = unit_vector(cross(self.vup, self.w))  # camera right
        self.v = cross(self.w, self.u)  # camera up

        # The viewport lies on the focus plane; its width follows the rounded
        # pixel count, not the nominal aspect ratio (as in RTIOW).
        h = math.tan(math.radians(self.vfov) / 2.0)
        viewport_height = 2.0 * h * self.focus_distance
        viewport_width = viewport_height * self.width / self.height
        viewport_u = self.u * viewport_width  # left edge -> right edge
        viewport_v = self.v * -viewport_height  # top edge -> bottom edge
        self.pixel_delta_u = viewport_u / self.width
        self.pixel_delta_v = viewport_v / self.height
        focus_center = self.look_from - self.w * self.focus_distance
        upper_left = focus_center - viewport_u / 2.0 - viewport_v / 2.0
        self.pixel00 = upper_left + (self.pixel_delta_u + self.pixel_delta_v) * 0.5
        radius = self.focus_distance * math.tan(math.radians(self.defocus_angle / 2.0))
        self.defocus_disk_u = self.u * radius
        self.defocus_disk_v = self.v * radius

    def with_width(self, width: int) -> Camera:
        """The same camera with another image width (height follows the aspect ratio)."""
        return Camera(
            self.look_from,
            self.look_at,
            self.vup,
            self.vfov,
            self.aspect_ratio,
            width,
            self.defocus_angle,
            self.focus_distance,
        )

    def _ray_through(self, px: float, py: float) -> Ray:
        """Ray through the viewport at fractional pixel position (px, py)."""
        # BEGIN SOLUTION week03: unit ray from the eye (or lens) through pixel position (px, py)
        target = self.pixel00 + self.pixel_delta_u * px + self.pixel_delta_v * py
        origin = self.look_from
        if self.defocus_angle > 0.0:
            d = random_in_unit_disk()
            origin = origin + self.defocus_disk_u * d.x() + self.defocus_disk_v * d.y()
        return Ray(origin, unit_vector(target - origin))
        # END SOLUTION

    def get_center_ray(self, i: int, j: int) -> Ray:
        """The ray through the center of pixel (i, j)."""
        # BEGIN SOLUTION week03: the ray through the center of pixel (i, j)
        return self._ray_through(float(i), float(j))
        # END SOLUTION

    def get_ray(self, i: int, j: int) -> Ray:
        """A ray through a uniformly random point of pixel (i, j) (a box filter)."""
        # BEGIN SOLUTION week03: a ray through a uniformly random point of pixel (i, j)
        r = generator().random
        return self._ray_through(i + r() - 0.5, j + r() - 0.5)
        # END SOLUTION


def checked_parameters(
    look_from, look_at, vup, vfov, aspect_ratio, width, defocus_angle, focus_distance
) -> tuple:
    """Camera's parameters, checked and converted (aspect_ratio "16:9" -> 1.777...),
    or ValueError/TypeError naming the parameter: finite points, a view of some
    length, an up vector across it, an image of at most MAX_PIXELS pixels."""
    look_from = checked_point("look_from", look_from)
    look_at = checked_point("look_at", look_at)
    vup = checked_edge("vup", vup)
    vfov = checked_number("vfov", vfov, VFOV)
    if isinstance(aspect_ratio, str):
        try:
            aspect_ratio = parse_aspect_ratio(aspect_ratio)
        except ValueError:
            raise ValueError(
                f'aspect_ratio: expected a number or "W:H", found {aspect_ratio!r}'
            ) from None
    aspect_ratio = checked_number("aspect_ratio", aspect_ratio, ASPECT_RATIO)
    width = SETTINGS["width"].check(width)
    defocus_angle = checked_number("defocus_angle", defocus_angle, DEFOCUS_ANGLE)
    focus_distance = checked_number("focus_distance", focus_distance, LENGTH)
    height = width / aspect_ratio
    if not height < 1e9:
        raise ValueError(f"aspect_ratio {aspect_ratio} makes the image {height} pixels high")
    height = max(1, int(height))
    if width * height > MAX_PIXELS:
        raise ValueError(
            f"width {width} x height {height} is {width * height:,} "
            f"pixels; the most is {MAX_PIXELS:,} (about 3 GB of memory)"
        )
    view = look_from - look_at
    if view.length() not in LENGTH:
        raise ValueError(
            f"look_at: expected a distance from look_from {LENGTH.text()}, "
            f"found {view.length():.3g}"
        )
    if not cross(vup, unit_vector(view)).length() >= MIN_SINE * vup.length():
        raise ValueError(
            "vup: expected an up vector across the view direction (look_at - look_from), "
            f"the sine of the angle between them >= {MIN_SINE:g}; found it parallel"
        )
    return look_from, look_at, vup, vfov, aspect_ratio, width, defocus_angle, focus_distance
