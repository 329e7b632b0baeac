"""Materials, registered by the name scene files use for them.

| name            | class        | parameters (defaults)                          |
|-----------------|--------------|------------------------------------------------|
| "lambertian"    | Lambertian   | albedo ([0.5, 0.5, 0.5])                        |
| "mirror"        | Mirror       | albedo ([1, 1, 1])                              |
| "metal"         | Metal        | albedo ([0.5, 0.5, 0.5]), fuzz (0)              |
| "dielectric"    | Dielectric   | ior (1.5), albedo ([1, 1, 1])                   |
| "rough_dielectric" | RoughDielectric | ior (1.5), roughness (0.1), distribution |
|                 |              | ("ggx"; or "beckmann"), tint ([1, 1, 1])        |
| "diffuse_light" | DiffuseLight | emit (required), two_sided (false)             |
| "phong"         | Phong        | albedo ([0.5, 0.5, 0.5]), kd (1), ks (0), exponent (1) |
| "blinn_phong"   | BlinnPhong   | albedo ([0.5, 0.5, 0.5]), kd (1), ks (0), exponent (1) |
| "oren_nayar"    | OrenNayar    | albedo ([0.5, 0.5, 0.5]), sigma (20, degrees, < 90) |
| "cook_torrance" | CookTorrance | albedo ([0.5, 0.5, 0.5]), kd (1), ks (0), roughness (0.5), |
|                 |              | distribution ("ggx"; or "beckmann"), ior (1.5), f0 (from ior) |
| "ward"          | Ward         | albedo ([0.5, 0.5, 0.5]), kd (1), ks (0), alpha_x (0.2), |
|                 |              | alpha_y (= alpha_x)                            |

Blinn is BlinnPhong under the course's name. The course's module functions of
RT_material.py are here too, each defined once: reflect, refract and halfvector
(rtpy/vec3.py) and schlick (rtpy/materials/dielectric.py).
"""

from ..vec3 import halfvector, reflect, refract
from .blinn_phong import Blinn, BlinnPhong
from .cook_torrance import CookTorrance
from .dielectric import Dielectric, schlick
from .diffuse_light import DiffuseLight
from .lambertian import Lambertian
from .material import Material
from .metal import Metal
from .mirror import Mirror
from .oren_nayar import OrenNayar
from .phong import Phong
from .rough_dielectric import RoughDielectric
from .ward import Ward

MATERIALS: dict[str, type[Material]] = {
    "lambertian": Lambertian,
    "mirror": Mirror,
    "metal": Metal,
    "dielectric": Dielectric,
    "rough_dielectric": RoughDielectric,
    "diffuse_light": DiffuseLight,
    "phong": Phong,
    "blinn_phong": BlinnPhong,
    "oren_nayar": OrenNayar,
    "cook_torrance": CookTorrance,
    "ward": Ward,
}


def register_material(name: str):
    """Class decorator: make a Material subclass usable as `type = "name"` in scene files.
    Its constructor's keyword parameters become the keys of [materials.X]. A name that
    is not a non-empty string, or a decorated object that is not a Material subclass,
    is a TypeError at once (not when a scene uses it)."""
    if not (isinstance(name, str) and name.strip()):
        raise TypeError(f"register_material: the name must be a non-empty string, got {name!r}")

    def decorate(cls: type[Material]) -> type[Material]:
        if not (isinstance(cls, type) and issubclass(cls, Material)):
            raise TypeError(
                f"register_material({name!r}): expected a subclass of Material, got {cls!r}"
            )
        MATERIALS[name] = cls
        return cls

    return decorate


__all__ = [
    "MATERIALS",
    "Blinn",
    "BlinnPhong",
    "CookTorrance",
    "Dielectric",
    "DiffuseLight",
    "Lambertian",
    "Material",
    "Metal",
    "Mirror",
    "OrenNayar",
    "Phong",
    "RoughDielectric",
    "Ward",
    "halfvector",
    "reflect",
    "refract",
    "register_material",
    "schlick",
]
