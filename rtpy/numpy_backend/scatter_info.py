"""ScatterBatch: N sampled bounces as arrays, the batched twin of the scalar ScatterInfo."""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .arrays import put_rows

# The Whitted rays of a batch of hits (Material.specular_rays): entry k holds every
# hit's k-th ray as (direction (N, 3), weight (N, 3), mask (N,) bool: the hit has one).
SpecularRays = list[tuple[np.ndarray, np.ndarray, np.ndarray]]


@dataclass
class ScatterBatch:
    """N sampled bounces, all zero where not alive.

    direction    (N, 3) unit directions leaving the surface (ScatterInfo.scattered_ray's;
                 the integrator spawns the rays from the hit points)
    attenuation  (N, 3) the sample's weight BRDF * cos / pdf, or a specular bounce's
                 weight (ScatterInfo.attenuation)
    pdf          (N,) solid-angle densities (0 for specular samples, as ScatterInfo)
    alive        (N,) bool: False where scattering() returns None (absorbed)
    is_specular  (N,) bool: delta bounces (ScatterInfo.is_specular)
    """

    direction: np.ndarray
    attenuation: np.ndarray
    pdf: np.ndarray
    alive: np.ndarray
    is_specular: np.ndarray

    @classmethod
    def absorbed(cls, n: int) -> ScatterBatch:
        """n samples that all return None."""
        return cls(
            np.zeros((n, 3)), np.zeros((n, 3)), np.zeros(n), np.zeros(n, bool), np.zeros(n, bool)
        )

    @classmethod
    def alive_at(
        cls,
        n: int,
        rows: np.ndarray | slice,
        direction: np.ndarray,
        attenuation: np.ndarray,
        pdf: np.ndarray,
    ) -> ScatterBatch:
        """n samples: non-specular bounces with these values at `rows`, absorbed at
        the other rows."""
        out = cls.absorbed(n)
        out.direction[rows] = direction
        out.attenuation[rows] = attenuation
        out.pdf[rows] = pdf
        out.alive[rows] = True
        return out

    def __len__(self) -> int:
        return len(self.pdf)

    def put(self, index: np.ndarray | slice, part: ScatterBatch) -> None:
        """Write `part` into the rows `index`."""
        if isinstance(index, slice):
            self.direction[index] = part.direction
            self.attenuation[index] = part.attenuation
        else:
            put_rows(self.direction, index, part.direction)
            put_rows(self.attenuation, index, part.attenuation)
        self.pdf[index] = part.pdf
        self.alive[index] = part.alive
        self.is_specular[index] = part.is_specular
