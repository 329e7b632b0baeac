"""Kernel of DiffuseLight (rtpy/materials/diffuse_light.py)."""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ...materials import DiffuseLight
from ..arrays import where_rows
from ..hit_info import HitBatch
from .material import Kernel, color_param


class DiffuseLightKernel(Kernel):
    """Emits `emit` from the front face (or both faces when two_sided), scatters nothing."""

    emits = True

    def __init__(self, materials: Sequence[DiffuseLight]) -> None:
        super().__init__(materials)
        self.emit = color_param(self.materials, "emit")
        self.two_sided = np.array([bool(m.two_sided) for m in self.materials])

    def emitting(self, slots: np.ndarray, hits: HitBatch) -> np.ndarray:
        on = hits.front_face | self.two_sided.take(slots)
        return where_rows(on, self.emit.take(slots, axis=0))
