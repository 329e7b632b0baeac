"""rtpy.scatter_info.ScatterInfo: the record of one sampled bounce."""

from __future__ import annotations

import pytest

from rtpy.ray import Ray
from rtpy.scatter_info import ScatterInfo
from rtpy.vec3 import Color, Vec3


def test_a_bounce_is_diffuse_with_no_density_unless_told():
    ray = Ray(Vec3(0, 0, 0), Vec3(0, 0, 1))
    s = ScatterInfo(ray, Color(0.5, 0.5, 0.5))
    assert (s.scattered_ray, s.attenuation, s.pdf, s.is_specular) == (
        ray,
        Color(0.5, 0.5, 0.5),
        0.0,
        False,
    )
    glass = ScatterInfo(ray, Color(1, 1, 1), is_specular=True)
    assert glass.is_specular and glass.pdf == 0.0


def test_a_record_holds_its_four_fields_only():
    s = ScatterInfo(Ray(Vec3(0, 0, 0), Vec3(0, 0, 1)), Color(1, 1, 1), 0.25)
    with pytest.raises(AttributeError):
        s.ray = None  # a misspelt field is an error, not a new attribute
    text = repr(s)
    assert text.startswith("ScatterInfo(scattered_ray=") and "pdf=0.25" in text
