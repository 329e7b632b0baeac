"""The Ward kernel at a grazing viewer."""

from __future__ import annotations

from rtpy.materials import Ward
from rtpy.vec3 import Color

from .kernel_checks import compare_with_scalar_sampler


def test_glossy_grazing_viewer_is_absorbed_as_in_scalar():
    """Viewers at 89 degrees: most specular samples fall below the surface."""
    material = Ward(Color(0.5, 0.5, 0.5), kd=0.1, ks=0.9, alpha_x=0.5, alpha_y=0.05)
    batched = compare_with_scalar_sampler(material, 89.0, 90.0)
    assert 0.1 < 1.0 - batched.scattered.mean() < 0.9
