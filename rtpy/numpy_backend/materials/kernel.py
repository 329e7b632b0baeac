"""ScatterBatch and the Kernel base class: the batched twin of one material class."""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ...materials.material import Material
from ..arrays import put_rows
from ..hits import HitBatch
from ..textures import TextureTable
from .frame import Rows

# One specular ray per hit for each entry: (direction (n, 3), weight (n, 3), mask (n,)).
SpecularRays = list[tuple[np.ndarray, np.ndarray, np.ndarray]]


@dataclass
class ScatterBatch:
    """N sampled bounces, the batched ScatterInfo (all zero where not alive).

    direction  (N, 3) unit directions leaving the surface
    weight     (N, 3) BRDF * cos / pdf, or a specular bounce's weight
    pdf        (N,) solid-angle densities (0 for specular samples, as ScatterInfo)
    alive      (N,) bool: False where scattering() returns None (absorbed)
    specular   (N,) bool: delta bounces (ScatterInfo.is_specular)
    """

    direction: np.ndarray
    weight: np.ndarray
    pdf: np.ndarray
    alive: np.ndarray
    specular: np.ndarray

    @classmethod
    def absorbed(cls, n: int) -> ScatterBatch:
        """n samples that all return None."""
        return cls(
            np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n), np.zeros(n, bool), np.zeros(n, bool)
        )

    def __len__(self) -> int:
        return len(self.pdf)

    def put(self, index: np.ndarray | slice, part: ScatterBatch) -> None:
        """Write `part` into the rows `index`."""
        if isinstance(index, slice):
            self.direction[index] = part.direction
            self.weight[index] = part.weight
        else:
            put_rows(self.direction, index, part.direction)
            put_rows(self.weight, index, part.weight)
        self.pdf[index] = part.pdf
        self.alive[index] = part.alive
        self.specular[index] = part.specular


class Kernel:
    """Batched twin of one material class, for all its instances in a table.

    A kernel holds its instances' parameters as arrays indexed by slot (the instance's
    position in `materials`); every method gets the slot of each hit and gathers the
    parameters it needs, so one call serves any number of instances. The defaults are
    those of the scalar Material base class: no scattering, no BRDF, no emission,
    white flat colour. The flags let the table skip calls that would return them.
    """

    evaluates = False  # eval() can be non-zero (a BRDF that is a function)
    scatters = False  # sample() can return live samples
    emits = False  # emitted() can be non-zero
    has_specular_rays = False  # specular_rays() can return rays

    def __init__(self, materials: Sequence[Material]) -> None:
        self.materials = list(materials)

    def flat_color(self, slots: np.ndarray, hits: HitBatch) -> np.ndarray:
        return np.ones((len(slots), 3))

    def emitted(self, slots: np.ndarray, hits: HitBatch) -> np.ndarray:
        return np.zeros((len(slots), 3))

    def eval(
        self, slots: np.ndarray, hits: HitBatch, wi: np.ndarray
    ) -> tuple[np.ndarray, np.ndarray]:
        return np.zeros((len(slots), 3)), np.zeros(len(slots))

    def sample(self, slots: np.ndarray, hits: HitBatch, rng: np.random.Generator) -> ScatterBatch:
        return ScatterBatch.absorbed(len(slots))

    def specular_rays(self, slots: np.ndarray, hits: HitBatch) -> SpecularRays:
        return []


class AlbedoKernel(Kernel):
    """A kernel whose materials have a texture `albedo` (the flat colour)."""

    def __init__(self, materials: Sequence[Material]) -> None:
        super().__init__(materials)
        self.albedo_table = TextureTable([m.albedo for m in self.materials])

    def albedo(self, slots: np.ndarray, hits: HitBatch, rows: Rows = slice(None)) -> np.ndarray:
        """(n, 3) albedo of the instances `slots` at the hits `rows` of `hits`."""
        return self.albedo_table.value(slots, hits, rows)

    def flat_color(self, slots: np.ndarray, hits: HitBatch) -> np.ndarray:
        return self.albedo(slots, hits)


def param(materials: Sequence[Material], name: str) -> np.ndarray:
    """(M,) float array of one scalar parameter of every instance."""
    return np.array([float(getattr(m, name)) for m in materials])


def color_param(materials: Sequence[Material], name: str) -> np.ndarray:
    """(M, 3) float array of one colour parameter of every instance."""
    return np.array([tuple(getattr(m, name)) for m in materials], dtype=np.float64).reshape(-1, 3)
