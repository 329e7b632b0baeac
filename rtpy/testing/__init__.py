"""Testing tools that users run on their own code: statistical checks of a
material (`check_material`, `assert_material` and the single checks), the
statistics they rest on, scenes whose exact image is known
(rtpy.testing.analytic_scenes) and reference renders (rtpy.testing.reference).

    from rtpy.testing import check_material
    print(check_material(MyMaterial(...)))

The names below load their module on first use, so that importing one module
(rtpy.testing.statistics for a render's memory figure) does not load them all.
"""

from __future__ import annotations

import importlib

# name -> the module of this package that defines it
_HOME = {
    "ABSORBED": "local_setup",
    "AdaptiveSimpson2D": "quadrature",
    "AlbedoEstimate": "material_checks",
    "CellRequest": "quadrature",
    "CheckResult": "material_checks",
    "Chi2Result": "chi_square",
    "LocalMaterial": "subject",
    "MaterialReport": "material_report",
    "MaterialSubject": "subject",
    "SCATTERED": "local_setup",
    "SPECULAR": "local_setup",
    "Samples": "local_setup",
    "as_subject": "subject",
    "assert_material": "material_report",
    "bonferroni_alpha": "statistics",
    "bonferroni_z": "statistics",
    "brdf_between": "local_setup",
    "check_energy": "material_checks",
    "check_material": "material_report",
    "check_non_negative_finite": "pointwise_checks",
    "check_reciprocity": "pointwise_checks",
    "check_weights": "material_checks",
    "chi2_sf": "statistics",
    "chi2_test": "chi_square",
    "directional_albedo": "material_checks",
    "draw_samples": "local_setup",
    "gamma_q": "statistics",
    "incident_ray": "local_setup",
    "integrate_cells": "quadrature",
    "light_ray": "local_setup",
    "local_direction": "local_setup",
    "local_hit": "local_setup",
    "material_name": "material_report",
    "normal_quantile": "statistics",
    "per_point": "quadrature",
    "sidak_alpha": "statistics",
    "view_ray": "local_setup",
}
__all__ = sorted(_HOME)


def __getattr__(name: str):
    home = _HOME.get(name)
    if home is None:
        raise AttributeError(f"module {__name__!r} has no attribute {name!r}")
    value = getattr(importlib.import_module(f".{home}", __name__), name)
    globals()[name] = value  # found directly from now on
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(__all__))
