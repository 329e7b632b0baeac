"""check_material: every check of a material at once, and its report.

How a student uses it::

    from rtpy.testing import check_material
    print(check_material(MyMaterial(...)))

prints a table with one line per check and incident angle, for example::

    check           angle  result  p-value   details
    chi2             30.0  pass    0.4121    100000 samples in 1152 bins (...)
    weights          30.0  FAIL    -         17 of 2000 samples: attenuation != ...

`assert_material(MyMaterial(...))` does the same in a test and raises an
AssertionError with that table when a check fails. A failing check says what
disagrees, at which incident angle, with a p-value for the statistical ones.
Statistical tests fail by chance with probability alpha; check_material divides
its alpha over the incident angles (Sidak), so a correct material passes all of
them with probability 1 - alpha.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass
from pathlib import Path

from ..materials.material import Material
from ..texture import Texture
from ..vec3 import Vec3
from .chi_square import chi2_test
from .local_setup import Samples, color_text
from .material_checks import CheckResult, check_energy, check_weights
from .pointwise_checks import check_non_negative_finite, check_reciprocity
from .statistics import sidak_alpha
from .subject import MaterialSubject, as_subject, material_of

__all__ = ["MaterialReport", "assert_material", "check_material", "material_name"]


def material_name(material: Material | MaterialSubject) -> str:
    """ClassName(parameter=value, ...) from the material's simple attributes (a
    subject of another process: its `name`, else its class name)."""
    if not isinstance(material, Material):
        inner = material_of(material)
        if inner is None:
            return str(getattr(material, "name", type(material).__name__))
        material = inner
    parts = []
    for key, value in getattr(material, "__dict__", {}).items():
        if key.startswith("_"):
            continue
        if isinstance(value, bool | int | float | str):
            parts.append(f"{key}={value:g}" if isinstance(value, float) else f"{key}={value!r}")
        elif isinstance(value, Vec3):
            parts.append(f"{key}={color_text(value)}")
        elif isinstance(value, Texture) and hasattr(value, "color"):
            parts.append(f"{key}={color_text(value.color)}")
    return f"{type(material).__name__}({', '.join(parts)})"


@dataclass
class MaterialReport:
    """All checks of check_material; `passed` is True when every check passed."""

    material: str
    checks: list[CheckResult]
    alpha: float
    seconds: float = 0.0
    picture: Path | None = None  # the picture of the first failed chi2 check, if drawn

    @property
    def passed(self) -> bool:
        return all(c.passed for c in self.checks)

    @property
    def failures(self) -> list[CheckResult]:
        return [c for c in self.checks if not c.passed]

    def __bool__(self) -> bool:
        return self.passed

    def __str__(self) -> str:
        n_fail = len(self.failures)
        verdict = "PASSED" if self.passed else f"FAILED ({n_fail} of {len(self.checks)} checks)"
        lines = [
            f"{self.material}: {verdict}",
            f"{'check':<12} {'angle':>7}  {'result':<7} {'p-value':<9} details",
        ]
        for c in self.checks:
            result = "skipped" if c.skipped else ("pass" if c.passed else "FAIL")
            p = "-" if c.p_value is None else f"{c.p_value:.3g}"
            lines.append(f"{c.check:<12} {c.angle_text:>7}  {result:<7} {p:<9} {c.detail}")
        if not self.passed:
            lines.append(_hints(self.failures))
        if self.picture is not None:
            lines.append(f"picture of the first failed chi2 check: {self.picture}")
        lines.append(
            f"(chi2 tests reject at p < {self.alpha:.3g} each: alpha Sidak-corrected over "
            f"the incident angles and sides; {self.seconds:.1f} s)"
        )
        return "\n".join(lines)


_HINTS = {
    "chi2": "chi2: scattering() does not draw directions with the density pdf() returns "
    "(compare the sampling formula with pdf(), its normalisation and its frame).",
    "weights": "weights: the attenuation must be BRDF * cos / pdf for the sampled direction.",
    "energy": "energy: the mean weight and the integral of BRDF * cos disagree, or exceed 1 "
    "(check the BRDF's normalisation, and that sampling covers every direction "
    "where the BRDF is not 0).",
    "reciprocity": "reciprocity: BRDF(wo, wi) must equal BRDF(wi, wo) (across a refracting "
    "surface, each over the index of refraction squared on its side).",
    "finite >= 0": "finite >= 0: guard divisions by cosines that reach 0 at grazing angles.",
}


def _hints(failures: list[CheckResult]) -> str:
    seen = dict.fromkeys(c.check for c in failures)
    return "\n".join("hint: " + _HINTS[name] for name in seen if name in _HINTS)


def _run(
    check: str, incident_deg: float | None, fn: Callable[[], CheckResult], inside: bool = False
) -> CheckResult:
    try:
        return fn()
    except Exception as error:  # a crash is a failed check, reported like the others
        detail = f"raised {type(error).__name__}: {error}"
        return CheckResult(check, incident_deg, False, detail, inside=inside)


def check_material(
    material: Material | MaterialSubject,
    incident_angles: Sequence[float] = (0.0, 30.0, 60.0, 85.0, 89.9),
    n_samples: int = 100_000,
    alpha: float = 0.01,
    reciprocal: bool = True,
    seed: int = 0,
    max_albedo: float | None = 1.0,
    theta_bins: int = 24,
    phi_bins: int = 48,
    inside: bool | None = None,
    ior: float | None = None,
    picture: str | Path | None = None,
) -> MaterialReport:
    """Run every check on `material` and return a MaterialReport (print it).

    Per incident angle: chi2_test, check_weights, check_energy (its <= max_albedo
    part skipped when max_albedo is None); once: check_reciprocity (when
    `reciprocal`) and check_non_negative_finite. The chi2 and energy tests use
    the per-test significance sidak_alpha(alpha, number of angles and sides). One
    set of n_samples draws per angle serves the chi2, weights and energy checks.

    A material that transmits (glass: some sample went below the surface) is
    checked from both sides: every angle from outside and from inside it, the
    energy over the whole sphere (reflected plus transmitted), and reciprocity
    across the surface too, with `ior` the index of refraction inside over outside
    (default: the material's own `ior`). inside=True or False forces checking
    from inside, or not. picture: a PNG file to draw the first failed chi2 check in
    (rtpy.testing.chi_square_picture); nothing is written when every one passes.
    """
    start = time.perf_counter()
    name = material_name(material)
    material = as_subject(material)
    angles = [float(t) for t in incident_angles]
    checks: list[CheckResult] = []
    if material.is_specular:
        checks = [
            CheckResult("chi2", theta, True, "specular material: no density", skipped=True)
            for theta in angles
        ]
        checks.append(
            _run("finite >= 0", None, lambda: check_non_negative_finite(material, seed=seed))
        )
        a = sidak_alpha(alpha, max(1, len(angles)))
        return MaterialReport(name, checks, a, time.perf_counter() - start)
    outside = {theta: _draw(material, theta, n_samples, seed, False) for theta in angles}
    transmits = any(
        not isinstance(s, CheckResult) and bool(s.transmitted.any()) for s in outside.values()
    )
    sides = (False, True) if (transmits if inside is None else inside) else (False,)
    a = sidak_alpha(alpha, max(1, len(angles) * len(sides)))
    options = dict(theta_bins=theta_bins, phi_bins=phi_bins, two_sided=transmits)
    options["failed_chi2"] = []  # (Chi2Result, angle, inside) of each failed chi2 check
    options["max_albedo"] = math.inf if max_albedo is None else max_albedo
    for side in sides:
        for theta in angles:
            samples = outside[theta] if not side else _draw(material, theta, n_samples, seed, True)
            if isinstance(samples, CheckResult):
                checks.append(samples)  # scattering() raised
                continue
            checks += _checks_at(material, samples, a, options)
    if reciprocal:
        if ior is None and transmits:
            ior = getattr(material_of(material) or material, "ior", None)
        checks.append(
            _run("reciprocity", None, lambda: check_reciprocity(material, seed=seed, ior=ior))
        )
    for side in sides:
        checks.append(
            _run(
                "finite >= 0",
                None,
                lambda side=side: check_non_negative_finite(material, seed=seed, inside=side),
            )
        )
    report = MaterialReport(name, checks, a, time.perf_counter() - start)
    if picture is not None and options["failed_chi2"]:
        report.picture = _picture(picture, options["failed_chi2"][0], material, name)
    return report


def _picture(path: str | Path, failed: tuple, material: MaterialSubject, name: str) -> Path:
    """The picture of a failed chi2 check (its Chi2Result, angle and side) at path."""
    from .chi_square_picture import chi2_picture

    result, theta, side = failed
    return chi2_picture(result, path, theta, material, inside=side, title=name)


def _draw(subject: MaterialSubject, theta: float, n: int, seed: int, inside: bool):
    """The subject's draws, or a failed CheckResult when scattering() raised."""
    try:
        return subject.draw(theta, n, seed=seed, inside=inside)
    except Exception as error:
        detail = f"raised {type(error).__name__}: {error}"
        return CheckResult("scattering", theta, False, detail, inside=inside)


def _checks_at(
    material: MaterialSubject, samples: Samples, a: float, options: dict
) -> list[CheckResult]:
    """The chi2, weights and energy checks of one set of samples."""
    theta, inside = samples.incident_deg, samples.inside

    def chi2() -> CheckResult:
        bins = dict(theta_bins=options["theta_bins"], phi_bins=options["phi_bins"])
        r = chi2_test(material, theta, samples=samples, inside=inside, **bins)
        ok = r.passed(a)
        if not ok:
            options["failed_chi2"].append((r, theta, inside))
        detail = r.summary(worst=not ok)
        return CheckResult("chi2", theta, ok, detail, p_value=r.p_value, inside=inside)

    def weights() -> CheckResult:
        return check_weights(material, theta, samples=samples, inside=inside)

    def energy() -> CheckResult:
        return check_energy(
            material,
            theta,
            alpha=a,
            max_albedo=options["max_albedo"],
            samples=samples,
            inside=inside,
            two_sided=options["two_sided"],
        )

    return [
        _run("chi2", theta, chi2, inside),
        _run("weights", theta, weights, inside),
        _run("energy", theta, energy, inside),
    ]


def assert_material(material: Material | MaterialSubject, **options) -> MaterialReport:
    """check_material, raising AssertionError with the report's table when a check fails
    (picture=PATH: with the picture of the first failed chi2 check drawn there)."""
    report = check_material(material, **options)
    if not report.passed:
        raise AssertionError("\n" + str(report))
    return report
