"""The "whitted" integrator: the scalar estimator, ray by ray, where it is deterministic."""

from __future__ import annotations

from .integrator_checks import check_ray_by_ray


def test_deterministic_case_matches_scalar_ray_by_ray():
    check_ray_by_ray("whitted")
