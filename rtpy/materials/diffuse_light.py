"""DiffuseLight: an emitting surface (an area light when put on an object)."""

from __future__ import annotations

from .._checks import boolean, checked
from ..hit_info import HitInfo
from ..vec3 import BLACK, Color
from .material import Material, material_color


class DiffuseLight(Material):
    """Emits radiance `emit` (W / (m^2 sr) per channel, the same in every
    direction) from its front face, or from both faces when two_sided.
    Scatters nothing."""

    is_emitter = True

    def __init__(self, emit: Color, two_sided: bool = False) -> None:
        self.emit = material_color("emit", emit)
        self.two_sided = checked("two_sided", boolean, two_sided)

    def emitting(self, hit: HitInfo) -> Color:
        if hit.front_face or self.two_sided:
            return self.emit
        return BLACK
