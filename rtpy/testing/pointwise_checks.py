"""The checks of a material at chosen directions, without statistics: reciprocity
(BRDF(wo, wi) == BRDF(wi, wo), or its generalised form across a refracting surface)
and finite values (BRDF, pdf and samples finite and >= 0, down to grazing angles).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np

from ..materials.material import Material
from ..sampling import generator, make_generator, use_generator
from .local_setup import (
    NON_NEGATIVE,
    RECIPROCITY,
    close,
    color_text,
    local_direction,
    vector_text,
)
from .material_checks import CheckResult
from .subject import MaterialSubject, as_subject

__all__ = ["GRAZING_ANGLES", "check_non_negative_finite", "check_reciprocity"]


def check_reciprocity(
    material: Material | MaterialSubject,
    n_pairs: int = 2000,
    seed: int = 0,
    rel_tol: float = 1e-9,
    ior: float | None = None,
) -> CheckResult:
    """BRDF(wo -> wi) == BRDF(wi -> wo) for random pairs of directions above the
    surface (uniform on the hemisphere, a quarter of them within 1 degree of it).

    With ior, for a material that transmits (ior: the index of refraction inside
    over outside), half of the pairs lie across the surface and the viewer is
    inside the material for half of them. Across the surface the BSDF for radiance
    obeys the generalised reciprocity of refraction (Veach 1997, section 5.2)

        BRDF(wo -> wi) / eta_o^2 == BRDF(wi -> wo) / eta_i^2,

    eta_o and eta_i the indices of refraction on the sides of wo and wi.
    """
    subject = as_subject(material)
    pairs = []
    with use_generator(make_generator(seed, RECIPROCITY)):
        r = generator().random
        for k in range(n_pairs):
            dirs = []
            for _ in range(2):
                if k % 4 == 3:
                    theta = 89.0 + r()  # grazing
                else:
                    theta = math.degrees(math.acos(r()))  # uniform on the hemisphere
                dirs.append(local_direction(theta, 360.0 * r()).tolist())
            a, b = dirs
            inside, across, eta_a, eta_b = False, False, 1.0, 1.0
            if ior is not None:
                inside, across = r() < 0.5, r() < 0.5
                if across:  # b below the surface, on the other side
                    b = [b[0], b[1], -b[2]]
                    eta_a, eta_b = (ior, 1.0) if inside else (1.0, ior)
            pairs.append((a, b, inside, across, eta_a, eta_b))
    if not pairs:
        return CheckResult("reciprocity", None, True, "0 direction pairs")
    # A viewer inside is the setup turned over: brdf_between(a, b, inside=True) is
    # brdf_between(turned a, turned b), so every pair goes in the same two calls.
    a_rows = np.array([_turned(a) if inside else a for a, _, inside, *_ in pairs])
    b_rows = np.array([_turned(b) if inside else b for _, b, inside, *_ in pairs])
    forward = np.asarray(subject.brdf(a_rows, b_rows), dtype=float).tolist()
    swapped = np.asarray(subject.brdf(b_rows, a_rows), dtype=float).tolist()
    failures, first = 0, ""
    for (a, b, inside, across, eta_a, eta_b), f_ab, f_ba in zip(
        pairs, forward, swapped, strict=True
    ):
        x = tuple(c / (eta_a * eta_a) for c in f_ab)
        y = tuple(c / (eta_b * eta_b) for c in f_ba)
        if not all(close(p, q, rel_tol) for p, q in zip(x, y, strict=True)):
            failures += 1
            if not first:
                where = " (viewer inside)" if inside else ""
                first = (
                    f"e.g. wo = {vector_text(a)}, wi = {vector_text(b)}"
                    f"{where}: BRDF {color_text(x)}, swapped {color_text(y)}"
                )
                if across:
                    first += " (each over the index of refraction squared on its side)"
    if failures:
        return CheckResult(
            "reciprocity", None, False, f"{failures} of {n_pairs} pairs differ; {first}"
        )
    across = f", across the surface with ior {ior:g} too" if ior is not None else ""
    return CheckResult("reciprocity", None, True, f"{n_pairs} direction pairs{across}")


def _turned(v: list[float]) -> list[float]:
    """v turned over (half a turn about the tangent x), as local_setup.turned_over."""
    return [v[0], -v[1], -v[2]]


GRAZING_ANGLES = (0.0, 30.0, 60.0, 85.0, 89.0, 89.9, 89.999)
_LIGHT_THETAS = (0.0, 10.0, 30.0, 45.0, 60.0, 80.0, 89.0, 89.9, 89.999, 90.0, 120.0, 180.0)
_LIGHT_PHIS = (0.0, 45.0, 90.0, 135.0, 180.0, 270.0)


def check_non_negative_finite(
    material: Material | MaterialSubject,
    incident_angles: Sequence[float] = GRAZING_ANGLES,
    n: int = 500,
    seed: int = 0,
    inside: bool = False,
) -> CheckResult:
    """BRDF, pdf, scattering weights and pdfs finite and >= 0 (and scattered
    directions finite), for incident angles down to grazing, light directions on
    a grid over the sphere plus the mirror, the retro-reflection and the straight
    through directions, and n samples of scattering() per incident angle.
    (A specular sample's weight is not seen: Samples keep only its status.)"""
    subject = as_subject(material)
    setups = [(float(theta), phi) for theta in incident_angles for phi in (0.0, 60.0)]
    grid = [local_direction(t, p).tolist() for t in _LIGHT_THETAS for p in _LIGHT_PHIS]
    wo_rows, wi_rows = [], []
    for theta, phi in setups:
        wo = local_direction(theta, phi).tolist()
        lights = [*grid, [-wo[0], -wo[1], wo[2]], wo, [-wo[0], -wo[1], -wo[2]]]
        wo_rows += [wo] * len(lights)
        wi_rows += lights
    # The whole grid of every incident direction in one brdf() and one pdf() call.
    wo_rows, wi_rows = np.array(wo_rows).reshape(-1, 3), np.array(wi_rows).reshape(-1, 3)
    f = np.asarray(subject.brdf(wo_rows, wi_rows, inside=inside), dtype=float)
    p = np.asarray(subject.pdf(wo_rows, wi_rows, inside=inside), dtype=float)
    with np.errstate(invalid="ignore"):
        bad = ~(np.isfinite(f) & (f >= 0.0)).all(axis=1) | ~(np.isfinite(p) & (p >= 0.0))
    per_setup = len(wo_rows) // max(1, len(setups))
    problems: list[str] = []
    for s, (theta, phi) in enumerate(setups):
        for k in np.flatnonzero(bad[s * per_setup : (s + 1) * per_setup]) + s * per_setup:
            problems.append(
                f"incident {theta:g} deg, wi {vector_text(wi_rows[k])}: "
                f"BRDF {color_text(f[k].tolist())}, pdf {float(p[k])!r}"
            )
        draws = subject.draw(theta, n, seed=seed, phi_deg=phi, inside=inside, tag=NON_NEGATIVE)
        weights, pdfs, dirs = draws.weights, draws.pdfs, draws.directions
        with np.errstate(invalid="ignore"):
            bad_weight = ~((np.isfinite(weights) & (weights >= 0.0)).all(axis=1))
            bad_weight |= ~(np.isfinite(pdfs) & (pdfs >= 0.0))
        bad_direction = ~np.isfinite(dirs).all(axis=1)
        for k in np.flatnonzero(draws.scattered & (bad_weight | bad_direction)):
            if bad_weight[k]:
                problems.append(
                    f"incident {theta:g} deg: sample weight {color_text(weights[k].tolist())}, "
                    f"pdf {float(pdfs[k])!r}"
                )
            else:
                problems.append(f"incident {theta:g} deg: direction {vector_text(dirs[k])}")
    if problems:
        detail = f"{len(problems)} bad values; e.g. {problems[0]}"
        return CheckResult("finite >= 0", None, False, detail, inside=inside)
    detail = f"incident angles {', '.join(f'{t:g}' for t in incident_angles)}"
    return CheckResult("finite >= 0", None, True, detail, inside=inside)
