"""Materials, registered by the name scene files use for them.

| name            | class        | parameters (defaults)                          |
|-----------------|--------------|------------------------------------------------|
| "lambertian"    | Lambertian   | albedo ([0.5, 0.5, 0.5])                        |
| "mirror"        | Mirror       | albedo ([1, 1, 1])                              |
| "metal"         | Metal        | albedo ([0.5, 0.5, 0.5]), fuzz (0)              |
| "dielectric"    | Dielectric   | ior (1.5), albedo ([1, 1, 1])                   |
| "diffuse_light" | DiffuseLight | emit (required), two_sided (false)             |
"""

from .dielectric import Dielectric, schlick
from .diffuse_light import DiffuseLight
from .lambertian import Lambertian
from .material import Material
from .metal import Metal
from .mirror import Mirror

MATERIALS: dict[str, type[Material]] = {
    "lambertian": Lambertian,
    "mirror": Mirror,
    "metal": Metal,
    "dielectric": Dielectric,
    "diffuse_light": DiffuseLight,
}


def register_material(name: str):
    """Class decorator: make a Material subclass usable as `type = "name"` in scene files.
    Its constructor's keyword parameters become the keys of [materials.X]."""

    def decorate(cls: type[Material]) -> type[Material]:
        MATERIALS[name] = cls
        return cls

    return decorate


__all__ = [
    "MATERIALS",
    "Dielectric",
    "DiffuseLight",
    "Lambertian",
    "Material",
    "Metal",
    "Mirror",
    "register_material",
    "schlick",
]
