"""Batched material kernels: the numpy twins of rtpy.materials, one file per material.

MaterialTable (table.py) turns a scene's materials into one kernel per material
class; a kernel (material.py) has the scalar Material's methods for many hits at
once. Materials without a kernel run through their scalar methods (fallback.py).
"""

from .material import Kernel
from .table import KERNELS, MaterialTable, class_name, kernel_class

__all__ = ["KERNELS", "Kernel", "MaterialTable", "class_name", "kernel_class"]
