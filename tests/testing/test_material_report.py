"""Tests for rtpy.testing.material_report: check_material runs every check and
reports them; assert_material raises with the report."""

from __future__ import annotations

import pytest

from rtpy.materials import Lambertian, Mirror
from rtpy.testing import assert_material, check_material

from .materials_to_check import CrashesAtGrazing, DiffuseTransmitter, OverNormalised, UpperPdfOnly


@pytest.mark.slow
def test_check_material_passes_lambertian_and_reports_every_check():
    report = check_material(Lambertian())
    assert report.passed, str(report)
    text = str(report)
    for name in ("chi2", "weights", "energy", "reciprocity", "finite >= 0"):
        assert name in text
    for theta in ("0", "30", "60", "85", "89.9"):
        assert f" {theta} " in text
    assert "PASSED" in text
    assert len([c for c in report.checks if c.check == "chi2"]) == 5
    assert all(c.p_value is not None for c in report.checks if c.check == "chi2")


def test_check_material_skips_density_checks_for_specular_materials():
    report = check_material(Mirror(), incident_angles=(30.0,))
    assert report.passed
    assert all(c.skipped for c in report.checks if c.check == "chi2")


def test_assert_material_reports_failures():
    with pytest.raises(AssertionError) as info:
        assert_material(OverNormalised(), incident_angles=(30.0,), n_samples=20_000)
    text = str(info.value)
    assert "FAILED" in text and "chi2" in text and "FAIL " in text and "hint" in text
    report = check_material(OverNormalised(), incident_angles=(30.0,), n_samples=20_000)
    failed = {c.check for c in report.failures}
    # scattering() records the true pdf cos / pi, pdf() says 1.1 cos / pi: weights
    # fails too; energy and reciprocity are fine.
    assert failed == {"chi2", "weights"}


def test_check_material_reports_a_crash_as_a_failed_check():
    report = check_material(CrashesAtGrazing(), incident_angles=(30.0,), n_samples=2000)
    assert not report.passed
    assert "raised ZeroDivisionError" in str(report)


@pytest.mark.slow
def test_check_material_checks_a_material_that_transmits_from_both_sides():
    report = check_material(DiffuseTransmitter(), incident_angles=(30.0,), n_samples=5000)
    assert report.passed, str(report)
    chi2 = [c for c in report.checks if c.check == "chi2"]
    assert [c.inside for c in chi2] == [False, True]
    assert len([c for c in report.checks if c.check == "finite >= 0"]) == 2
    text = str(report)
    assert "   30 in  pass" in text and "transmitted 0.5000" in text
    front = check_material(DiffuseTransmitter(), (30.0,), n_samples=5000, inside=False)
    assert not any(c.inside for c in front.checks)
    broken = check_material(UpperPdfOnly(), incident_angles=(30.0,), n_samples=5000)
    assert {(c.check, c.inside) for c in broken.failures} >= {("chi2", False), ("chi2", True)}


def test_a_failed_chi2_check_can_be_drawn(tmp_path):
    """picture=PATH: the first failed chi2 check is drawn there and the report (and
    assert_material's message) names the file; a material whose chi2 checks pass
    writes nothing."""
    from PIL import Image

    from .materials_to_check import UniformSampler

    path = tmp_path / "uniform.png"
    with pytest.raises(AssertionError, match="picture of the first failed chi2 check: .*uniform"):
        assert_material(UniformSampler(), incident_angles=(30.0,), n_samples=5000, picture=path)
    assert Image.open(path).format == "PNG"
    fine = tmp_path / "fine.png"
    report = check_material(Lambertian(), incident_angles=(30.0,), n_samples=5000, picture=fine)
    assert report.passed and report.picture is None and not fine.exists()
