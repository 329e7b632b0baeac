"""rtpy.cli.bench.convergence: the convergence check holds for every unbiased
integrator on the analytic scenes and catches biased ones.

The convergence check (BenchResult.problems) fails a series when any level has a
significant bias (z-test against the noise measured over independent renders,
Bonferroni-corrected over the run's levels at family-wise level 1e-3) or when
the fitted slope of log MSE against log spp is outside -1 +- 0.15.

Why +- 0.15 is a principled bound here: the fit reports the slope's standard
error (from the spread of the per-pixel squared errors at each level), and
test_slope_standard_error_is_small_enough requires it to be at most 0.15 / 4,
so an unbiased series fails the slope test with probability below 1e-4 (a
4-sigma two-sided normal tail). Checked by repetition: over 4 seed sets the
glowing furnace's slopes (16 px wide, 4 repeats) spread by 0.01-0.02 around
-1.00 with reported errors of 0.03; at 8 px wide the spread (0.05) also matched
the reported error (0.055), which is why these runs are 16 px wide. Seeds are
fixed, so the tests are deterministic.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from rtpy.cli.bench.convergence import ROUNDING, SLOPE_TOLERANCE, BenchResult, fit_slope
from rtpy.cli.bench.run import run_bench
from rtpy.cli.bench.scenes import VARIANTS

SPP = (1, 4, 16, 64)
REPEATS = 4
WIDTH = 16
NOISY = ["plane_point_light", "plane_sphere_light", "plane_sky_band", "glowing_furnace"]


def quiet(_msg: str) -> None:
    pass


@pytest.fixture(scope="module")
def unbiased():
    """Every variant on every analytic scene; the plane scenes 24 px wide (their
    error is uneven over the image, so they need more pixels for the same
    precision of the slope), the furnaces 16 px."""
    parts = [
        run_bench(
            scenes,
            backends=("numpy",),
            variants=tuple(VARIANTS),
            spps=SPP,
            repeats=REPEATS,
            width=width,
            log=quiet,
        )
        for scenes, width in ((NOISY[:3], 24), (["glowing_furnace", "furnace"], WIDTH))
    ]
    merged = BenchResult(
        levels=[lv for p in parts for lv in p.levels], fits=[f for p in parts for f in p.fits]
    )
    merged.finish()  # Bonferroni over all the levels
    return merged


@pytest.mark.slow
def test_every_unbiased_integrator_passes_the_convergence_check(unbiased):
    assert unbiased.problems() == []
    fitted = {(f.scene, f.integrator) for f in unbiased.fits if f.slope is not None}
    # every integrator on every noisy scene has a slope (direct is exact in the
    # glowing furnace: light sampling a sphere from inside has no variance)
    expected = {(s, v) for s in NOISY for v in VARIANTS} - {("glowing_furnace", "direct")}
    assert fitted == expected
    for f in unbiased.fits:
        if f.slope is not None:
            assert abs(f.slope + 1) < SLOPE_TOLERANCE, f


@pytest.mark.slow
def test_slope_standard_error_is_small_enough(unbiased):
    for f in unbiased.fits:
        if f.slope is not None:
            assert 0 < f.slope_se <= SLOPE_TOLERANCE / 4, f


@pytest.mark.slow
def test_exact_scenes_have_zero_error(unbiased):
    """The convex furnace (every sample exact) and direct light inside the glowing
    sphere have no error beyond rounding: no slope to fit, and no bias."""
    for lv in unbiased.levels:
        if lv.scene == "furnace" or (lv.scene == "glowing_furnace" and lv.integrator == "direct"):
            assert lv.rmse <= ROUNDING, lv
            assert not lv.significant


@pytest.mark.slow
def test_nee_only_and_mis_agree_with_the_exact_image(unbiased):
    """On the sphere-light plane, light sampling alone, BRDF sampling alone and MIS
    all converge to the closed form, and MIS is the most efficient at 64 spp."""
    last = {lv.integrator: lv for lv in unbiased.levels if lv.scene == "plane_sphere_light"}
    assert {lv.spp for lv in last.values()} == {64}
    for lv in last.values():
        assert abs(lv.bias_z) < unbiased.z_critical
    assert last["path-brdf"].rel_mse > 5 * last["path-mis"].rel_mse


def drop_one_over_pdf(monkeypatch):
    """A planted mistake: BRDF sampling weights BRDF * cos instead of BRDF * cos / pdf."""
    from rtpy.numpy_backend.materials.table import MaterialTable

    original = MaterialTable.scattering

    def scattering(self, ids, hits, rng):
        sc = original(self, ids, hits, rng)
        keep = sc.is_specular | ~sc.alive
        sc.attenuation = np.where(keep[:, None], sc.attenuation, sc.attenuation * sc.pdf[:, None])
        return sc

    monkeypatch.setattr(MaterialTable, "scattering", scattering)


def count_light_twice(monkeypatch):
    """A planted mistake: emission found by BRDF sampling keeps weight 1 although
    light sampling also counts it."""
    from rtpy.numpy_backend.integrators import direct_lighting

    monkeypatch.setattr(direct_lighting, "emission_weight", lambda _, obj, *a: np.ones(len(obj)))


@pytest.mark.parametrize(
    "plant,scenes",
    [
        (drop_one_over_pdf, ["plane_sky_band", "furnace", "glowing_furnace"]),
        (count_light_twice, ["plane_sphere_light", "glowing_furnace"]),
    ],
)
def test_a_biased_integrator_is_caught_by_the_same_check(monkeypatch, plant, scenes):
    plant(monkeypatch)
    result = run_bench(
        scenes, ("numpy",), ("path-mis",), SPP, repeats=REPEATS, width=WIDTH, log=quiet
    )
    problems = result.problems()
    for scene in scenes:
        assert any(p.startswith(f"{scene}/") for p in problems), (scene, problems)


def uniform_directions_with_cosine_weights(monkeypatch):
    """A planted mistake that a furnace cannot see: directions drawn uniformly over
    the hemisphere but weighted as if drawn by the cosine (weight = albedo). In a
    uniform environment every sample is still exactly the albedo; under the sky
    band, grazing directions are drawn too often."""
    from rtpy.numpy_backend.materials.table import MaterialTable

    original = MaterialTable.scattering

    def scattering(self, ids, hits, rng):
        sc = original(self, ids, hits, rng)
        d = rng.normal(size=sc.direction.shape)
        d /= np.linalg.norm(d, axis=1, keepdims=True)
        d *= np.sign(np.einsum("ij,ij->i", d, hits.normal))[:, None]
        diffuse = sc.alive & ~sc.is_specular
        sc.direction = np.where(diffuse[:, None], d, sc.direction)
        return sc

    monkeypatch.setattr(MaterialTable, "scattering", scattering)


def test_a_wrong_pdf_at_grazing_angles_is_caught_by_the_sky_band_only(monkeypatch):
    uniform_directions_with_cosine_weights(monkeypatch)
    result = run_bench(
        ["furnace", "plane_sky_band"],
        ("numpy",),
        ("path-brdf",),
        SPP,
        repeats=REPEATS,
        width=WIDTH,
        log=quiet,
    )
    problems = result.problems()
    assert problems and all(p.startswith("plane_sky_band/") for p in problems), problems


def test_fit_slope_recovers_a_known_slope_and_its_error():
    rng = np.random.default_rng(0)
    spp = np.array([1, 4, 16, 64, 256])
    slopes = []
    for _ in range(200):
        rel = 0.05
        mse = 3.0 * spp**-1.0 * np.exp(rng.normal(0, rel, spp.size))
        slope, se = fit_slope(spp, mse, mse * rel)
        slopes.append(slope)
    assert se == pytest.approx(rel / math.sqrt(((np.log(spp) - np.log(spp).mean()) ** 2).sum()))
    assert abs(np.mean(slopes) + 1) < 4 * se / math.sqrt(200)
    assert np.std(slopes) == pytest.approx(se, rel=0.2)
    assert fit_slope([4], [1.0], [0.1]) == (None, None)
