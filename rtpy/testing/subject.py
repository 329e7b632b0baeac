"""What the material checks ask of a material: a MaterialSubject.

The checks (chi2_test, check_weights, check_energy, check_reciprocity,
check_non_negative_finite, check_material) never call a Material's methods
themselves: they ask a subject, in batches, so that the material may live in
another process (a grader's untrusted child) and every call is one round trip.
LocalMaterial is the subject of an rtpy Material in this process; the checks
accept either and turn a Material into one with as_subject.

Directions are unit vectors in the local test setup (see local_setup.py): wo
toward the viewer, wi toward the light, rows of (m, 3) float arrays.
"""

from __future__ import annotations

from typing import Protocol, runtime_checkable

import numpy as np

from ..materials.material import Material
from ..vec3 import Vec3
from .local_setup import (
    SAMPLING,
    Samples,
    brdf_between,
    light_ray,
    local_hit,
    scatter_draws,
    view_ray,
)

__all__ = ["LocalMaterial", "MaterialSubject", "as_subject"]


@runtime_checkable
class MaterialSubject(Protocol):
    """A material as the checks see it: three batched questions."""

    is_specular: bool

    def draw(
        self,
        incident_deg: float,
        n: int,
        *,
        seed: int = 0,
        phi_deg: float = 0.0,
        inside: bool = False,
        tag: int = SAMPLING,
    ) -> Samples:
        """n draws of scattering() for the incoming ray of the test setup, under
        local_setup.sampling_generator(seed, tag, incident_deg, phi_deg, inside)."""
        ...

    def brdf(self, wo: np.ndarray, wi: np.ndarray, *, inside: bool = False) -> np.ndarray:
        """(m, 3): brdf_between(material, wo[k], wi[k], inside) for every row k (a
        viewer below the surface turns the setup over)."""
        ...

    def pdf(self, wo: np.ndarray, wi: np.ndarray, *, inside: bool = False) -> np.ndarray:
        """(m,): material.pdf(view_ray(wo[k]), light_ray(wi[k]), local_hit(material,
        inside)) for every row k."""
        ...


def _vectors(rows: np.ndarray) -> list[Vec3]:
    return [Vec3(x, y, z) for x, y, z in np.asarray(rows, dtype=float).reshape(-1, 3).tolist()]


class LocalMaterial:
    """The MaterialSubject of an rtpy Material in this process: every batch is a
    loop over the material's own methods, in row order."""

    def __init__(self, material: Material) -> None:
        if not isinstance(material, Material):
            raise TypeError(f"material: expected an rtpy Material, got {type(material).__name__}")
        self.material = material
        self.is_specular = bool(material.is_specular)

    def __repr__(self) -> str:
        return f"LocalMaterial({self.material!r})"

    def draw(
        self,
        incident_deg: float,
        n: int,
        *,
        seed: int = 0,
        phi_deg: float = 0.0,
        inside: bool = False,
        tag: int = SAMPLING,
    ) -> Samples:
        return scatter_draws(self.material, incident_deg, n, seed, phi_deg, inside, tag)

    def brdf(self, wo: np.ndarray, wi: np.ndarray, *, inside: bool = False) -> np.ndarray:
        m = self.material
        out = [
            brdf_between(m, a, b, inside).tolist()
            for a, b in zip(_vectors(wo), _vectors(wi), strict=True)
        ]
        return np.array(out, dtype=float).reshape(-1, 3)

    def pdf(self, wo: np.ndarray, wi: np.ndarray, *, inside: bool = False) -> np.ndarray:
        pdf, hit = self.material.pdf, local_hit(self.material, inside)
        out = [
            pdf(view_ray(a), light_ray(b), hit)
            for a, b in zip(_vectors(wo), _vectors(wi), strict=True)
        ]
        return np.array(out, dtype=float)


def as_subject(x: Material | MaterialSubject) -> MaterialSubject:
    """x itself when it is a MaterialSubject, else LocalMaterial(x)."""
    if isinstance(x, Material):
        return LocalMaterial(x)
    if isinstance(x, MaterialSubject):
        return x
    raise TypeError(
        f"material: expected an rtpy Material or a MaterialSubject, got {type(x).__name__}"
    )


def material_of(subject: MaterialSubject) -> Material | None:
    """The in-process Material behind a subject, or None (a remote one)."""
    return subject.material if isinstance(subject, LocalMaterial) else None
