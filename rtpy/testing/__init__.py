"""Checking renderers and materials against ground truth: the material checks a
student runs on a BRDF (`check_material`), statistics, scenes with exact images and
reference renders."""

from .material_checks import *  # noqa: F403
from .material_checks import SCATTERED  # noqa: F401
