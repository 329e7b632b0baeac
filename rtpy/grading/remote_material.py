"""A material graded in the student's process, as rtpy.testing's checks see one.

`RemoteMaterial(probe, spec)` is a rtpy.testing.subject.MaterialSubject whose draws
and evaluations are the probes material_draw, material_brdf and material_pdf
(rtpy.grading.probes) of the material `spec` ({"type": "Phong", "albedo": [...],
...}). The checks (chi-square, weights, energy, reciprocity) then run in the judge on
what the student's code computed:

    result = rt.chi2_test(RemoteMaterial(probe, spec), 30.0, n_samples=10_000)
"""

from __future__ import annotations

import numpy as np

from ..testing.local_setup import SAMPLING, Samples
from .protocol import ProtocolError


class RemoteMaterial:
    def __init__(self, probe, spec: dict) -> None:
        self.probe, self.spec = probe, dict(spec)
        self._specular: bool | None = None

    @property
    def is_specular(self) -> bool:
        if self._specular is None:
            self._specular = self.probe.material_is_specular(material=self.spec)
        return self._specular

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
        table = self.probe.material_draw(
            material=self.spec, incident_deg=float(incident_deg), n=int(n), seed=int(seed),
            phi_deg=float(phi_deg), inside=bool(inside), tag=int(tag),
        )  # fmt: skip
        if len(table) != n:
            raise ProtocolError(f"asked for {n} draws of scattering(), got {len(table)}")
        status = table[:, 7]
        if not np.isin(status, (0.0, 1.0, 2.0)).all():
            raise ProtocolError("a draw of scattering() with a status that does not exist")
        return Samples(
            float(incident_deg),
            float(phi_deg),
            table[:, 0:3],
            table[:, 3:6],
            table[:, 6],
            status.astype(np.int8),
            0.0,
            bool(inside),
        )

    def brdf(self, wo: np.ndarray, wi: np.ndarray, *, inside: bool = False) -> np.ndarray:
        wo, wi = np.asarray(wo, dtype=float), np.asarray(wi, dtype=float)
        got = self.probe.material_brdf(material=self.spec, wo=wo, wi=wi, inside=bool(inside))
        return _rows(got, len(wo), "BRDF()")

    def pdf(self, wo: np.ndarray, wi: np.ndarray, *, inside: bool = False) -> np.ndarray:
        wo, wi = np.asarray(wo, dtype=float), np.asarray(wi, dtype=float)
        got = self.probe.material_pdf(material=self.spec, wo=wo, wi=wi, inside=bool(inside))
        return _rows(got, len(wo), "pdf()")


def _rows(values: np.ndarray, n: int, what: str) -> np.ndarray:
    if len(values) != n:
        raise ProtocolError(f"asked for {n} values of {what}, got {len(values)}")
    return values
