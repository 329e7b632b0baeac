"""The single checks of a material (chi2_test and check_energy aside, see
chi_square.py and energy.py).

A material has three functions that must agree (see rtpy/materials/material.py):
scattering() draws directions, pdf() claims the density it draws them with, and
BRDF() is f_r, so that every sample's weight is BRDF * |cos| / pdf. Each check
returns a CheckResult, true when the check passed:

- check_weights: is every sample's attenuation BRDF * |cos| / pdf, and the
  ScatterInfo's pdf the value pdf() returns?
- check_reciprocity: BRDF(wi, wo) == BRDF(wo, wi)? For a material that refracts,
  across the surface: BRDF(wo, wi) / eta_o^2 == BRDF(wi, wo) / eta_i^2.
- check_non_negative_finite: BRDF, pdf and weights finite and >= 0, also at
  grazing angles?

The checks that take an incident angle look from outside the material, or with
inside=True from inside it (glass seen from within; see local_setup.py).
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from ..materials.material import Material
from ..ray import Ray
from ..sampling import generator, make_generator, use_generator
from ..vec3 import Vec3
from .local_setup import (
    NON_NEGATIVE,
    ORIGIN,
    RECIPROCITY,
    Samples,
    brdf_between,
    close,
    color_text,
    get_samples,
    incident_ray,
    light_ray,
    local_direction,
    local_hit,
    sampling_generator,
    vector_text,
)

__all__ = [
    "GRAZING_ANGLES",
    "CheckResult",
    "check_non_negative_finite",
    "check_reciprocity",
    "check_weights",
]


@dataclass
class CheckResult:
    """One check at one incident angle (None for checks over all angles), from
    outside the material or (inside) from inside it.

    True in a boolean context when the check passed, so `assert check_weights(m, 30)`
    works and shows the details when it fails."""

    check: str
    incident_deg: float | None
    passed: bool
    detail: str
    p_value: float | None = None
    skipped: bool = False
    inside: bool = False

    def __bool__(self) -> bool:
        return self.passed

    @property
    def angle_text(self) -> str:
        """The incident angle in degrees ("all" for checks over all angles), with
        " in" when seen from inside."""
        angle = "all" if self.incident_deg is None else f"{self.incident_deg:g}"
        return angle + (" in" if self.inside else "")

    def __str__(self) -> str:
        angle = "all" if self.incident_deg is None else f"{self.incident_deg:g} deg"
        angle += " from inside" if self.inside else ""
        status = "skipped" if self.skipped else ("pass" if self.passed else "FAIL")
        p = "" if self.p_value is None else f", p = {self.p_value:.3g}"
        return f"{self.check} at {angle}: {status}{p}: {self.detail}"


def check_weights(
    material: Material,
    incident_deg: float,
    n: int = 2000,
    seed: int = 0,
    phi_deg: float = 0.0,
    samples: Samples | None = None,
    rel_tol: float = 1e-9,
    inside: bool = False,
) -> CheckResult:
    """For the first n scattered (non-specular) samples: attenuation ==
    BRDF(ray_in, scattered, hit) * |cos| / pdf(ray_in, scattered, hit) per channel,
    ScatterInfo.pdf == pdf(...), and the direction is a unit vector."""
    samples = get_samples(material, incident_deg, n, seed, phi_deg, samples, inside)
    ray_view = incident_ray(incident_deg, phi_deg)
    hit = local_hit(material, inside)
    idx = np.flatnonzero(samples.scattered)[:n]
    if len(idx) == 0:
        detail = "no scattered samples"
        return CheckResult("weights", incident_deg, True, detail, skipped=True, inside=inside)
    failures, first = 0, ""
    for k in idx:
        x, y, z = (float(c) for c in samples.directions[k])
        weight = [float(c) for c in samples.weights[k]]
        wi = Vec3(x, y, z)
        f = material.BRDF(ray_view, Ray(ORIGIN, wi), hit)
        pdf = material.pdf(ray_view, Ray(ORIGIN, wi), hit)
        length = math.sqrt(x * x + y * y + z * z)
        problem = ""
        if not abs(length - 1.0) <= 1e-9:
            problem = f"direction has length {length!r}"
        elif not close(float(samples.pdfs[k]), pdf, rel_tol):
            problem = f"ScatterInfo.pdf = {samples.pdfs[k]:.9g} but pdf() = {pdf:.9g}"
        elif not pdf > 0.0:
            problem = f"pdf() = {pdf!r} for a direction scattering() returned"
        else:
            expect = [c * abs(z) / pdf for c in (f.e0, f.e1, f.e2)]
            if not all(close(a, b, rel_tol) for a, b in zip(weight, expect, strict=True)):
                problem = (
                    f"attenuation {color_text(weight)} but BRDF * cos / pdf = {color_text(expect)}"
                )
        if problem:
            failures += 1
            if not first:
                theta = math.degrees(math.acos(max(-1.0, min(1.0, z / length))))
                first = f"e.g. wi = {vector_text((x, y, z))} (theta {theta:.2f} deg): {problem}"
    if failures:
        detail = f"{failures} of {len(idx)} samples wrong; {first}"
        return CheckResult("weights", incident_deg, False, detail, inside=inside)
    detail = f"{len(idx)} samples: attenuation = BRDF * cos / pdf"
    return CheckResult("weights", incident_deg, True, detail, inside=inside)


def check_reciprocity(
    material: Material,
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
    failures, first = 0, ""
    with use_generator(make_generator(seed, RECIPROCITY)):
        r = generator().random
        for k in range(n_pairs):
            dirs = []
            for _ in range(2):
                if k % 4 == 3:
                    theta = 89.0 + r()  # grazing
                else:
                    theta = math.degrees(math.acos(r()))  # uniform on the hemisphere
                dirs.append(local_direction(theta, 360.0 * r()))
            a, b = dirs
            inside, across, eta_a, eta_b = False, False, 1.0, 1.0
            if ior is not None:
                inside, across = r() < 0.5, r() < 0.5
                if across:  # b below the surface, on the other side
                    b = Vec3(b.e0, b.e1, -b.e2)
                    eta_a, eta_b = (ior, 1.0) if inside else (1.0, ior)
            f_ab = brdf_between(material, a, b, inside)
            f_ba = brdf_between(material, b, a, inside)
            x = tuple(c / (eta_a * eta_a) for c in (f_ab.e0, f_ab.e1, f_ab.e2))
            y = tuple(c / (eta_b * eta_b) for c in (f_ba.e0, f_ba.e1, f_ba.e2))
            if not all(close(p, q, rel_tol) for p, q in zip(x, y, strict=True)):
                failures += 1
                if not first:
                    where = " (viewer inside)" if inside else ""
                    first = (
                        f"e.g. wo = {vector_text(a.tolist())}, wi = {vector_text(b.tolist())}"
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


GRAZING_ANGLES = (0.0, 30.0, 60.0, 85.0, 89.0, 89.9, 89.999)
_LIGHT_THETAS = (0.0, 10.0, 30.0, 45.0, 60.0, 80.0, 89.0, 89.9, 89.999, 90.0, 120.0, 180.0)
_LIGHT_PHIS = (0.0, 45.0, 90.0, 135.0, 180.0, 270.0)


def check_non_negative_finite(
    material: Material,
    incident_angles: Sequence[float] = GRAZING_ANGLES,
    n: int = 500,
    seed: int = 0,
    inside: bool = False,
) -> CheckResult:
    """BRDF, pdf, scattering weights and pdfs finite and >= 0 (and scattered
    directions finite), for incident angles down to grazing, light directions on
    a grid over the sphere plus the mirror, the retro-reflection and the straight
    through directions, and n samples of scattering() per incident angle."""
    problems: list[str] = []
    hit = local_hit(material, inside)

    def bad_color(c) -> bool:
        return not all(math.isfinite(x) and x >= 0.0 for x in (c.e0, c.e1, c.e2))

    def bad_number(x) -> bool:
        return not (math.isfinite(x) and x >= 0.0)

    for theta in incident_angles:
        for phi in (0.0, 60.0):
            ray_in = incident_ray(theta, phi)
            wo = local_direction(theta, phi)
            lights = [local_direction(t, p) for t in _LIGHT_THETAS for p in _LIGHT_PHIS]
            lights += [Vec3(-wo.e0, -wo.e1, wo.e2), wo, Vec3(-wo.e0, -wo.e1, -wo.e2)]
            for wi in lights:
                f = material.BRDF(ray_in, light_ray(wi), hit)
                p = material.pdf(ray_in, light_ray(wi), hit)
                if bad_color(f) or bad_number(p):
                    problems.append(
                        f"incident {theta:g} deg, wi {vector_text(wi.tolist())}: "
                        f"BRDF {color_text(f)}, pdf {p!r}"
                    )
            with use_generator(sampling_generator(seed, NON_NEGATIVE, theta, phi, inside)):
                for _ in range(n):
                    s = material.scattering(ray_in, hit)
                    if s is None:
                        continue
                    d = s.scattered_ray.direction
                    if bad_color(s.attenuation) or bad_number(s.pdf):
                        problems.append(
                            f"incident {theta:g} deg: sample weight {color_text(s.attenuation)}, "
                            f"pdf {s.pdf!r}"
                        )
                    elif not all(math.isfinite(x) for x in (d.e0, d.e1, d.e2)):
                        problems.append(f"incident {theta:g} deg: direction {vector_text(d)}")
    if problems:
        detail = f"{len(problems)} bad values; e.g. {problems[0]}"
        return CheckResult("finite >= 0", None, False, detail, inside=inside)
    detail = f"incident angles {', '.join(f'{t:g}' for t in incident_angles)}"
    return CheckResult("finite >= 0", None, True, detail, inside=inside)
