"""Batched material kernels: the numpy twins of rtpy.materials.

MaterialTable turns a scene's materials into one kernel per material class (see
table.py); the kernels are in simple.py (Lambertian, Mirror, Metal, Dielectric,
DiffuseLight), glossy.py (Phong, Blinn-Phong, Cook-Torrance, Ward), oren_nayar.py and
fallback.py (any other material, through its scalar methods).
"""

from .kernel import Kernel, ScatterBatch
from .table import KERNELS, MaterialTable, kernel_class

__all__ = ["KERNELS", "Kernel", "MaterialTable", "ScatterBatch", "kernel_class"]
