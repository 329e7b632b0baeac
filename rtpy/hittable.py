"""Hittable: the interface every object in a scene has."""

from __future__ import annotations

import math
from typing import TYPE_CHECKING

from .hit_info import HitInfo
from .interval import Interval
from .ray import Ray
from .vec3 import Vec3, dot

# Light sampling gives no sample to a receiving point nearer than 1e-50 (d^2 < 1e-100)
# to the point it samples on a light, as to that point itself: there the 1 / d^2 of a
# point light's radiance or of an area light sample's weight exceeds 1e100, which times
# the brightest radiance and BRDF the scene format allows overflows (and below
# d^2 ~ 1e-308 it is inf outright).
MIN_LIGHT_DISTANCE2 = 1e-100

if TYPE_CHECKING:
    from .bvh import AABB
    from .materials.material import Material


class Hittable:
    """A surface a ray can hit.

    Subclasses implement `hit_t`, the cheap part (the ray parameter of the
    closest hit inside an interval, or None), and `hit_info`, which builds the
    full record for one t. `intersect` combines them, as the course's
    `intersect(ray, interval)`. The scene calls `hit_t` on the objects a ray may
    hit (all of them, or those its BVH cannot rule out by `bounding_box`) and
    `hit_info` only for the closest, so records are not built for hits that
    something nearer hides.
    """

    material: Material

    def hit_t(self, ray: Ray, t_min: float, t_max: float) -> float | None:
        """The smallest t > t_min at which the ray hits, if it is < t_max; else None.

        So a smaller t_max gives the same t or None, never another hit: the BVH,
        which tests objects out of list order, relies on it.
        """
        raise NotImplementedError

    def hit_info(self, ray: Ray, t: float) -> HitInfo:
        raise NotImplementedError

    def intersect(self, ray: Ray, interval: Interval) -> HitInfo | None:
        """The closest hit with interval.min < t < interval.max, or None."""
        t = self.hit_t(ray, interval.min, interval.max)
        if t is None:
            return None
        return self.hit_info(ray, t)

    def bounding_box(self) -> AABB | None:
        """An axis-aligned box containing the object, or None when it has none
        (unbounded); the BVH tests such objects on every ray."""
        return None

    def surface_uv(self, hit: HitInfo) -> tuple[float, float]:
        """Surface coordinates (u, v) of a hit on this object."""
        return 0.0, 0.0

    def surface_tangent(self, hit: HitInfo) -> Vec3 | None:
        """Unit tangent along increasing u at the hit, or None when the surface has
        no u direction there (then HitInfo.tangent picks any perpendicular)."""
        return None

    # --- as an area light ---------------------------------------------------
    # An object with an emitting material is also a light. Light sampling picks
    # a direction from a receiving point p toward the object; the renderer then
    # traces that direction to find the point and its emission. Densities are
    # per unit solid angle at p. The default samples the surface uniformly by
    # area and converts: pdf_solid_angle = pdf_area * distance^2 / |cos theta_light|.

    def area(self) -> float:
        raise NotImplementedError(f"{type(self).__name__} cannot be an area light")

    def sample_point(self, r1: float, r2: float) -> tuple[Vec3, Vec3]:
        """A point uniform over the surface from two uniform numbers in [0, 1),
        with the geometric unit normal there: (point, normal)."""
        raise NotImplementedError(f"{type(self).__name__} cannot be an area light")

    def sample_direction(self, p: Vec3, r1: float, r2: float) -> tuple[Vec3, float] | None:
        """A unit direction from p toward this object and its solid-angle pdf, or
        None when the sample is useless (p on the object's plane)."""
        point, normal = self.sample_point(r1, r2)
        to_point = point - p
        dist2 = to_point.length_squared()
        if dist2 < MIN_LIGHT_DISTANCE2:
            return None
        direction = to_point / math.sqrt(dist2)
        cos_light = abs(dot(direction, normal))
        if cos_light < 1e-12:
            return None
        return direction, area_to_solid_angle(dist2, cos_light, self.area())

    def sample_hit(self, p: Vec3, r1: float, r2: float) -> tuple[Vec3, float, HitInfo] | None:
        """Light sampling from p: (the unit direction sample_direction draws, its
        solid-angle pdf, the HitInfo where the ray from p along it meets this object,
        whose t is the distance), or None when the sample is useless. This traces the
        ray; a shape that knows the distance from the sample can skip that."""
        sample = self.sample_direction(p, r1, r2)
        if sample is None:
            return None
        direction, pdf = sample
        ray = Ray(p, direction)
        t = self.hit_t(ray, 0.0, math.inf)
        if t is None or not pdf > 0.0:
            return None  # a grazing sample that rounding moved off the shape
        return direction, pdf, self.hit_info(ray, t)

    def direction_pdf(self, p: Vec3, hit: HitInfo) -> float:
        """Solid-angle density with which sample_direction(p) picks the direction
        from p to `hit`, a point on this object."""
        to_point = hit.point - p
        dist2 = to_point.length_squared()
        if dist2 < MIN_LIGHT_DISTANCE2:  # never sampled (sample_direction)
            return 0.0
        cos_light = abs(dot(to_point, hit.normal)) / math.sqrt(dist2)
        if cos_light < 1e-12:
            return 0.0
        return area_to_solid_angle(dist2, cos_light, self.area())


class FlatShape(Hittable):
    """A flat shape (Quad, Triangle): the subclass sets `normal`, the unit normal of
    its front face, `_tangent`, its unit tangent along increasing u, and `_area`."""

    normal: Vec3
    _tangent: Vec3
    _area: float

    def surface_tangent(self, hit: HitInfo) -> Vec3 | None:
        return self._tangent

    def area(self) -> float:
        return self._area


def area_to_solid_angle(dist2, cos_light, area):
    """The solid-angle density at a point of a light point drawn uniformly by area:
    (1 / area) dist^2 / |cos theta_light|, dist2 the squared distance between them and
    cos_light = |cos theta_light| at the light (floats, or arrays in the numpy backend)."""
    return dist2 / (cos_light * area)
