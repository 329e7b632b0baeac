"""The ranges of the materials' parameters, by name: one table for the materials'
constructors (rtpy.materials.material's material_number and material_color) and the
scene loader (rtpy.io.scene_file, whose keys are the constructors' parameters).
"""

from __future__ import annotations

from .._checks import EXPONENT, FUZZ, IOR, RADIANCE, ROUGHNESS, SIGMA, UNIT, Range

__all__ = ["MATERIAL_RANGES"]

# Ranges of material parameters by name, for numbers and for each colour component.
# The scene loader and the materials' constructors check against these; a
# constructor's ValueError becomes a SceneError too.
MATERIAL_RANGES: dict[str, Range] = {
    "albedo": UNIT,
    "f0": UNIT,
    "emit": RADIANCE,
    "ior": IOR,
    "fuzz": FUZZ,
    "kd": UNIT,
    "ks": UNIT,
    "exponent": EXPONENT,
    "roughness": ROUGHNESS,
    "alpha_x": ROUGHNESS,
    "alpha_y": ROUGHNESS,
    "sigma": SIGMA,
    "tint": UNIT,
}
