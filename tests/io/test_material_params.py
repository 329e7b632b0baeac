"""Tests for rtpy.io.material_params: a material's scene keys are its constructor's
parameters, with its defaults, so materials registered later load unchanged."""

from __future__ import annotations

from rtpy.materials import Dielectric, DiffuseLight, Lambertian, Metal, Mirror
from rtpy.texture import SolidColor
from rtpy.vec3 import Color

from .scene_text import assert_names, error_of, load

GREY = Color(0.5, 0.5, 0.5)


def test_material_defaults_come_from_the_constructor():
    text = """
[materials.l]
type = "lambertian"
[materials.m]
type = "mirror"
[materials.t]
type = "metal"
[materials.g]
type = "dielectric"
[materials.e]
type = "diffuse_light"
emit = [1, 2, 3]
"""
    scene = load(
        text
        + "".join(
            f'[[objects]]\ntype = "sphere"\ncenter = [0, 0, {-i}]\nradius = 1\nmaterial = "{m}"\n'
            for i, m in enumerate("lmtge")
        )
    )
    mats = [o.material for o in scene.objects]
    assert isinstance(mats[0], Lambertian) and mats[0].albedo.color == Color(0.5, 0.5, 0.5)
    assert isinstance(mats[1], Mirror) and mats[1].albedo.color == Color(1, 1, 1)
    assert (
        isinstance(mats[2], Metal)
        and mats[2].fuzz == 0
        and mats[2].albedo.color == Color(0.5, 0.5, 0.5)
    )
    assert isinstance(mats[3], Dielectric) and mats[3].ior == 1.5
    assert isinstance(mats[4], DiffuseLight) and mats[4].two_sided is False
    assert mats[4].emit == Color(1, 2, 3)
    assert len(scene.area_lights) == 1


def test_unknown_key_in_material_uses_constructor_signature():
    err = error_of('[materials.m]\ntype = "metal"\nfuz = 0.1\n')
    assert_names(err, "[materials.m]", "fuz", "fuzz")
    assert "albedo" in str(err) and "fuzz" in str(err)


def test_constructor_value_errors_become_scene_errors(monkeypatch):
    from rtpy import materials

    class Fussy(Lambertian):
        def __init__(self, albedo: Color = GREY, level: float = 1.0) -> None:
            if level > 2:
                raise ValueError(f"fussy level must be <= 2, got {level}")
            super().__init__(albedo)

    monkeypatch.setitem(materials.MATERIALS, "fussy", Fussy)
    err = error_of('[materials.f]\ntype = "fussy"\nlevel = 3\n')
    assert_names(err, "[materials.f]", "level")
    assert "<= 2" in str(err)


def test_materials_registered_later_load_without_changing_the_loader(monkeypatch):
    from rtpy import materials

    class Shiny(Lambertian):
        def __init__(
            self,
            albedo: Color | None = None,
            kd: float = 1.0,
            ks: float = 0.0,
            exponent: float = 1,
            samples: int = 4,
            distribution: str = "ggx",
            f0: Color | None = None,
            fancy: bool = False,
        ) -> None:
            super().__init__(albedo if albedo is not None else Color(0.5, 0.5, 0.5))
            self.kd, self.ks, self.exponent, self.samples = kd, ks, exponent, samples
            self.distribution, self.f0, self.fancy = distribution, f0, fancy

    monkeypatch.setitem(materials.MATERIALS, "shiny", Shiny)
    head = '[textures.t]\ntype = "solid"\ncolor = [1, 1, 1]\n[materials.s]\ntype = "shiny"\n'
    obj = '[[objects]]\ntype = "sphere"\ncenter = [0, 0, -1]\nradius = 1\nmaterial = "s"\n'
    m = load(
        head + 'albedo = "t"\nks = 1\nexponent = 20.5\nsamples = 8\n'
        'distribution = "beckmann"\nf0 = [0.9, 0.8, 0.7]\nfancy = true\n' + obj
    )
    m = m.objects[0].material
    assert isinstance(m.albedo, SolidColor)
    assert (m.ks, m.exponent, m.samples, m.distribution, m.fancy) == (1, 20.5, 8, "beckmann", True)
    assert m.f0 == Color(0.9, 0.8, 0.7)
    m = load(head + obj).objects[0].material
    assert (m.kd, m.ks, m.exponent, m.samples, m.f0) == (1.0, 0.0, 1, 4, None)
    for bad, key in (
        ("ks = -1", "ks"),  # range table
        ("kd = true", "kd"),
        ("samples = 2.5", "samples"),  # annotated int
        ("distribution = 3", "distribution"),
        ("fancy = 1", "fancy"),
        ("f0 = [1, 1]", "f0"),
        ("f0 = [2, 0, 0]", "f0"),
        ('albedo = "nope"', "albedo"),
        ("exponent = nan", "exponent"),
        ("kdd = 1", "kdd"),
    ):
        err = error_of(head + bad + "\n")
        assert_names(err, "[materials.s]", key)
