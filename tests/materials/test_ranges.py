"""rtpy.materials.ranges: one range per material parameter, for the constructors and
the scene loader alike."""

from __future__ import annotations

import inspect

import pytest

from rtpy._checks import Range
from rtpy.materials import MATERIALS, Lambertian, Metal
from rtpy.materials.ranges import MATERIAL_RANGES


def test_every_range_names_a_parameter_of_a_registered_material():
    parameters = {name for cls in MATERIALS.values() for name in inspect.signature(cls).parameters}
    assert set(MATERIAL_RANGES) <= parameters
    assert all(isinstance(rng, Range) for rng in MATERIAL_RANGES.values())


def test_the_constructors_check_against_the_table():
    assert 1.0 in MATERIAL_RANGES["fuzz"] and -0.1 not in MATERIAL_RANGES["fuzz"]
    Metal(fuzz=1.0)
    with pytest.raises(ValueError, match=r"^fuzz: expected a number in \[0, 1000000\]"):
        Metal(fuzz=-0.1)
    with pytest.raises(ValueError, match=r"^albedo: expected an array of 3 finite numbers"):
        Lambertian(albedo=(0.5, 1.5, 0.5))
