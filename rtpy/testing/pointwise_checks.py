"""The checks of a material at chosen directions, without statistics: reciprocity
(BRDF(wo, wi) == BRDF(wi, wo), or its generalised form across a refracting surface)
and finite values (BRDF, pdf and samples finite and >= 0, down to grazing angles).
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from ..materials.material import Material
from ..sampling import generator, make_generator, use_generator
from ..vec3 import Vec3
from .local_setup import (
    NON_NEGATIVE,
    RECIPROCITY,
    brdf_between,
    close,
    color_text,
    incident_ray,
    light_ray,
    local_direction,
    local_hit,
    sampling_generator,
    vector_text,
)
from .material_checks import CheckResult

__all__ = ["GRAZING_ANGLES", "check_non_negative_finite", "check_reciprocity"]


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
