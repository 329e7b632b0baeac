"""Testing tools that users run on their own code: statistical checks of a
material (`check_material`, `assert_material` and the single checks), the
statistics they rest on, scenes whose exact image is known
(rtpy.testing.analytic_scenes) and reference renders (rtpy.testing.reference).

    from rtpy.testing import check_material
    print(check_material(MyMaterial(...)))
"""

from .chi_square import Chi2Result, chi2_test
from .local_setup import (
    ABSORBED,
    SCATTERED,
    SPECULAR,
    Samples,
    brdf_between,
    draw_samples,
    incident_ray,
    light_ray,
    local_direction,
    local_hit,
    view_ray,
)
from .material_checks import (
    AlbedoEstimate,
    CheckResult,
    check_energy,
    check_weights,
    directional_albedo,
)
from .material_report import MaterialReport, assert_material, check_material, material_name
from .pointwise_checks import check_non_negative_finite, check_reciprocity
from .quadrature import AdaptiveSimpson2D
from .statistics import (
    bonferroni_alpha,
    bonferroni_z,
    chi2_sf,
    gamma_q,
    normal_quantile,
    sidak_alpha,
)

__all__ = [
    "ABSORBED",
    "SCATTERED",
    "SPECULAR",
    "AdaptiveSimpson2D",
    "AlbedoEstimate",
    "CheckResult",
    "Chi2Result",
    "MaterialReport",
    "Samples",
    "assert_material",
    "bonferroni_alpha",
    "bonferroni_z",
    "brdf_between",
    "check_energy",
    "check_material",
    "check_non_negative_finite",
    "check_reciprocity",
    "check_weights",
    "chi2_sf",
    "chi2_test",
    "directional_albedo",
    "draw_samples",
    "gamma_q",
    "incident_ray",
    "light_ray",
    "local_direction",
    "local_hit",
    "material_name",
    "normal_quantile",
    "sidak_alpha",
    "view_ray",
]
