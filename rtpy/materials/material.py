"""Material: how a surface scatters and emits light.

Direction conventions (all directions are unit vectors):
- ray_view / ray_in: the ray arriving at the surface; its direction points
  TOWARD the surface. wo = -ray_view.direction points back to the viewer.
- ray_light: a ray LEAVING the surface toward the light; wi = ray_light.direction.
- hit.normal faces the arriving ray (dot(hit.normal, wo) >= 0).

A material has four separate methods, as in the course:
- scattering(ray_in, hit) samples an outgoing direction and returns a
  ScatterInfo whose attenuation is the Monte Carlo weight BRDF * cos / pdf;
- BRDF(ray_view, ray_light, hit) evaluates f_r (no cosine), in 1/sr;
- pdf(ray_view, ray_light, hit) is the solid-angle density with which
  scattering() picks ray_light's direction, so integrators can combine light
  sampling and BRDF sampling (multiple importance sampling);
- emitting(hit) is the emitted radiance toward the arriving ray.

Specular (delta) materials set `is_specular = True`: their BRDF and pdf are
not functions that can be evaluated, so integrators only follow the rays
scattering() returns and never sample lights at them.
"""

from __future__ import annotations

from .._checks import checked_color, checked_number
from ..hit_info import HitInfo
from ..ray import Ray
from ..scatter_info import ScatterInfo
from ..texture import SolidColor, Texture
from ..vec3 import BLACK, WHITE, Color
from .ranges import MATERIAL_RANGES


def material_number(name: str, value: float) -> float:
    """A material's number parameter as a float, in its range (MATERIAL_RANGES);
    TypeError or ValueError naming it."""
    return checked_number(name, value, MATERIAL_RANGES[name])


def material_color(name: str, value: Color) -> Color:
    """A material's colour parameter (a Color or 3 numbers), each component in its
    range (MATERIAL_RANGES); TypeError or ValueError naming it."""
    return checked_color(name, value, MATERIAL_RANGES[name])


def as_texture(albedo: Color | Texture, name: str = "albedo") -> Texture:
    """A texture as it is, a colour (a Color or 3 numbers in [0, 1]) as a SolidColor."""
    if isinstance(albedo, Texture):
        return albedo
    return SolidColor(material_color(name, albedo))


def check_strengths(kd: float, ks: float) -> tuple[float, float]:
    """(kd, ks) as floats, or ValueError unless both lie in [0, 1]."""
    return material_number("kd", kd), material_number("ks", ks)


class Material:
    is_specular = False  # True: delta scattering only (mirror, metal, glass)
    is_emitter = False  # True: emitting() may be non-zero (an area light)

    def scattering(self, ray_in: Ray, hit: HitInfo) -> ScatterInfo | None:
        """Sample a scattered ray; None when the light is absorbed."""
        return None

    def BRDF(self, ray_view: Ray, ray_light: Ray, hit: HitInfo) -> Color:
        """f_r(wi, wo) in 1/sr, without the cosine."""
        return BLACK

    def pdf(self, ray_view: Ray, ray_light: Ray, hit: HitInfo) -> float:
        """Solid-angle density of scattering() choosing ray_light.direction."""
        return 0.0

    def emitting(self, hit: HitInfo) -> Color:
        """Radiance emitted from the hit point back along the arriving ray."""
        return BLACK

    def flat_color(self, hit: HitInfo) -> Color:
        """The colour the "center" and "jittered" integrators show: the albedo
        (texture value) where the material has one, else white."""
        albedo = getattr(self, "albedo", None)
        return albedo.value(hit) if isinstance(albedo, Texture) else WHITE

    def specular_rays(self, ray_in: Ray, hit: HitInfo) -> list[tuple[Ray, Color]]:
        """For the Whitted integrator: the deterministic rays a specular material
        sends on and the fraction of light each carries. Empty for others."""
        return []
