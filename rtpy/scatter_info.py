"""ScatterInfo: one sampled bounce, the sample record of a material (like pbrt's BSDFSample)."""

from __future__ import annotations

from .ray import Ray
from .vec3 import Color


class ScatterInfo:
    """The result of Material.scattering().

    scattered_ray  the scattered ray, leaving the surface (direction is a unit vector)
    attenuation    the Monte Carlo weight of this sample, BRDF * cos(theta) / pdf with
                   theta the angle between the normal and the scattered direction, or
                   for a specular (delta) bounce the fraction of light carried. The
                   integrator multiplies the path's throughput by it, with no further
                   cosine or pdf. This is not the course's attenuation_color,
                   which is the BRDF value alone: here the cosine and 1/pdf are
                   already in (for a cosine-sampled Lambertian surface the weight is
                   exactly the albedo). See docs/course-map.md.
    pdf            solid-angle density the direction was drawn with (0 for specular)
    is_specular    True for delta bounces (mirror, metal, glass): no light sampling
                   there, and the pdf is not a density
    """

    __slots__ = ("scattered_ray", "attenuation", "pdf", "is_specular")

    def __init__(
        self, scattered_ray: Ray, attenuation: Color, pdf: float = 0.0, is_specular: bool = False
    ) -> None:
        self.scattered_ray = scattered_ray
        self.attenuation = attenuation
        self.pdf = pdf
        self.is_specular = is_specular

    def __repr__(self) -> str:
        return (
            f"ScatterInfo(scattered_ray={self.scattered_ray!r}, attenuation={self.attenuation!r}, "
            f"pdf={self.pdf!r}, is_specular={self.is_specular!r})"
        )
