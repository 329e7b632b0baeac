"""Tests for rtpy._checks: the typed values of scene files. Through the loader,
each wrong type or range is a SceneError naming the file, table and key; the
checks themselves say what was expected and found."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings

import rtpy
from rtpy import _checks as checks
from rtpy._checks import COORDINATE, LENGTH, RADIANCE, UNIT, Invalid, Range
from rtpy.camera import Camera
from rtpy.environment import SkyBand
from rtpy.io.material_params import material_parameters
from rtpy.light import PointLight
from rtpy.materials import MATERIALS, Lambertian
from rtpy.materials.ranges import MATERIAL_RANGES
from rtpy.mesh import Transform
from rtpy.quad import Quad
from rtpy.render_settings import RenderSettings
from rtpy.scene import Scene
from rtpy.sphere import Sphere
from rtpy.texture import CheckerTexture, SolidColor
from rtpy.triangle import Triangle
from rtpy.vec3 import Vec3

from .io.scene_text import MINIMAL, assert_names, error_of
from .strategies import SPECIAL_FLOATS, extreme_floats

LIGHT = '[[lights]]\ntype = "point"\nposition = [0, true, 0]\nintensity = [1, 1, 1]\n'


@pytest.mark.parametrize(
    "text, table, key, words",
    [
        ('[camera]\nvfov = "wide"\n', "[camera]", "vfov", ["expected a number", '"wide"']),
        ("[camera]\nlook_from = [1, 2]\n", "[camera]", "look_from", ["3"]),
        ('[render]\nsky = "yes"\n', "[render]", "sky", ["true or false"]),
        ("[render]\nnee = 1\n", "[render]", "nee", []),
        # an integer key: a float is refused with a hint
        ("[render]\nspp = 16.0\n", "[render]", "spp", ["integer", "write 16"]),
        ("[camera]\nwidth = 300.5\n", "[camera]", "width", []),
        # a boolean is not a number
        ("[camera]\nvfov = true\n", "[camera]", "vfov", []),
        ("[render]\nspp = true\n", "[render]", "spp", []),
        (LIGHT, "[[lights]] #1", "position", ["booleans are not numbers"]),
    ],
)
def test_a_value_of_the_wrong_type_is_refused(text, table, key, words):
    err = error_of(text)
    assert_names(err, table, key)
    for word in words:
        assert word in str(err)


@pytest.mark.parametrize("value", ["nan", "inf", "-inf", "+inf", "-nan"])
def test_nan_and_infinity_are_refused(value):
    err = error_of(MINIMAL.replace("radius = 0.5", f"radius = {value}"))
    assert_names(err, "[[objects]] #1", "radius")
    assert "finite" in str(err)
    err = error_of(MINIMAL.replace("center = [0, 0, -1]", f"center = [0, {value}, -1]"))
    assert_names(err, "[[objects]] #1", "center")
    err = error_of(f"[render]\ngamma = {value}\n")
    assert_names(err, "[render]", "gamma")


@pytest.mark.parametrize(
    ("text", "table", "key"),
    [
        ("[camera]\nvfov = 180\n", "[camera]", "vfov"),
        ("[camera]\nvfov = 0\n", "[camera]", "vfov"),
        ("[camera]\nwidth = 0\n", "[camera]", "width"),
        ("[camera]\nfocus_distance = 0\n", "[camera]", "focus_distance"),
        ("[camera]\ndefocus_angle = -1\n", "[camera]", "defocus_angle"),
        ("[camera]\naspect_ratio = -1.5\n", "[camera]", "aspect_ratio"),
        ("[render]\nspp = 0\n", "[render]", "spp"),
        ("[render]\nmax_depth = 0\n", "[render]", "max_depth"),
        ("[render]\nrussian_roulette = -1\n", "[render]", "russian_roulette"),
        ("[render]\nseed = -3\n", "[render]", "seed"),
        ("[render]\ngamma = 0\n", "[render]", "gamma"),
        ("[render]\nbackground = [0, -0.1, 0]\n", "[render]", "background"),
        ('[materials.m]\ntype = "lambertian"\nalbedo = [1.2, 0, 0]\n', "[materials.m]", "albedo"),
        ('[materials.m]\ntype = "lambertian"\nalbedo = [-0.1, 0, 0]\n', "[materials.m]", "albedo"),
        ('[materials.m]\ntype = "dielectric"\nior = 0\n', "[materials.m]", "ior"),
        ('[materials.m]\ntype = "metal"\nfuzz = -0.5\n', "[materials.m]", "fuzz"),
        ('[materials.m]\ntype = "diffuse_light"\nemit = [1, -1, 1]\n', "[materials.m]", "emit"),
        (
            '[textures.t]\ntype = "checker"\nscale = -1\neven = [0, 0, 0]\nodd = [1, 1, 1]\n',
            "[textures.t]",
            "scale",
        ),
        (
            '[[lights]]\ntype = "point"\nposition = [0, 0, 0]\nintensity = [1, 1, -1]\n',
            "[[lights]] #1",
            "intensity",
        ),
    ],
)
def test_out_of_range(text, table, key):
    err = error_of(text)
    assert_names(err, table, key)
    assert "expected" in str(err)


def test_negative_radius_is_refused():
    err = error_of(MINIMAL.replace("radius = 0.5", "radius = -0.5"))
    assert_names(err, "[[objects]] #1", "radius")
    assert "expected a number in [1e-06, 1000000], found -0.5" in str(err)


# --- the checks on their own -----------------------------------------------------------------


def invalid(check, *args) -> Invalid:
    with pytest.raises(Invalid) as info:
        check(*args)
    return info.value


def test_number_takes_integers_refuses_booleans_nan_and_values_out_of_range():
    assert checks.number(3, checks.POSITIVE) == 3.0 and isinstance(checks.number(3), float)
    assert checks.number(np.float32(0.5)) == 0.5
    e = invalid(checks.number, True)
    assert e.wrong_type and e.detail == "expected a number, found true"
    e = invalid(checks.number, math.nan, checks.POSITIVE)
    assert not e.wrong_type and e.detail == "expected a finite number > 0, found nan"
    assert (
        invalid(checks.number, 10**400).detail
        == "expected a finite number, found a very large integer"
    )
    e = invalid(checks.number, -1.5, Range(0, 180, True, True))
    assert e.detail == "expected a number in (0, 180), found -1.5" and not e.wrong_type


def test_integer_refuses_floats_with_a_hint_and_takes_numpy_integers():
    assert checks.integer(np.int64(7), checks.NON_NEGATIVE) == 7
    assert type(checks.integer(np.int64(7))) is int
    e = invalid(checks.integer, 16.0, Range(1, 100), " (larger counts are refused)")
    assert e.wrong_type
    assert e.detail == (
        "expected an integer in [1, 100] (larger counts are refused), found 16.0 "
        "(write 16 without the decimal point)"
    )
    assert invalid(checks.integer, 2.5).detail == "expected an integer, found 2.5"
    assert invalid(checks.integer, np.bool_(True)).wrong_type
    assert invalid(checks.integer, False).detail == "expected an integer, found false"
    assert invalid(checks.integer, 0, Range(1)).detail == "expected an integer >= 1, found 0"


def test_string_suggests_the_nearest_choice():
    assert checks.string("path", ("center", "path")) == "path"
    e = invalid(checks.string, "pth", ("center", "path"))
    assert e.detail == 'expected one of "center", "path", found the string "pth"'
    assert e.suggestion == "path" and not e.wrong_type
    assert invalid(checks.string, 3).detail == "expected a string, found 3"
    assert invalid(checks.string, "zzz", ("center", "path")).suggestion is None


def test_triple_names_the_bad_component():
    assert checks.triple([1, 2.5, 3]) == (1.0, 2.5, 3.0)
    each = "expected an array of 3 finite numbers, each in [0, 1]"
    assert invalid(checks.triple, [0, 2, 0], checks.UNIT).detail == (
        f"{each}, found [0, 2, 0] (component 2 is 2)"
    )
    e = invalid(checks.triple, [0, True, 0], checks.UNIT)
    assert e.wrong_type and e.detail.endswith(
        "found true as component 2 (booleans are not numbers)"
    )
    assert invalid(checks.triple, [1, 2]).detail.endswith("found [1, 2]")
    assert invalid(checks.triple, "red").detail.endswith('found the string "red"')


def test_describe_and_ranges():
    assert checks.describe([1, 2.5, True]) == "[1, 2.5, true]"
    assert checks.describe(list(range(9))) == "an array of 9 items"
    assert checks.describe({"a": 1}) == "a table"
    assert checks.describe("x" * 100) == "the string " + '"' + "x" * 56 + "..."
    assert checks.describe(2.0) == "2.0" and checks.describe(2**70) == "a very large integer"
    assert Range(0, 1).text() == "in [0, 1]" and Range(0, None, True).text() == "> 0"
    assert Range(None, 5, hi_open=True).text() == "< 5" and checks.ANY.text() == ""
    assert 0 not in Range(0, None, True) and 0 in Range(0) and 1e31 not in checks.RADIANCE
    assert math.nan not in checks.ANY and math.inf in checks.ANY
    assert checks.suggest("lookat", ["look_at", "look_from"]) == "look_at"


# --- the Python API: every constructor parameter over every magnitude ------------------------

GREY = (0.5, 0.5, 0.5)
# Examples per constructor parameter in the slow tier (log-uniform magnitudes
# and special values), on top of SPECIAL_FLOATS in the fast tier.
API_EXAMPLES = 25


def _inside(rng: Range):
    return lambda x: math.isfinite(x) and x in rng


def _material_cases() -> list[tuple[str, object, tuple[str, ...], object]]:
    """(label, build(x), the names its errors may give, x accepted?) for every number
    parameter of every material and one component of every colour parameter."""
    cases = []
    for kind, cls in MATERIALS.items():
        base = {"emit": (1.0, 1.0, 1.0)} if kind == "diffuse_light" else {}
        for p in material_parameters(cls).values():
            rng = MATERIAL_RANGES.get(p.name)
            if rng is None or p.kind not in ("float", "color", "albedo"):
                continue
            if p.kind == "float":

                def build(x, cls=cls, name=p.name, base=base):
                    return cls(**{**base, name: x})
            else:

                def build(x, cls=cls, name=p.name, base=base):
                    return cls(**{**base, name: (0.5, x, 0.5)})

            cases.append((f"{cls.__name__} {p.name}", build, (p.name,), _inside(rng)))
    return cases


def _vector_length_ok(x: float) -> bool:
    return math.isfinite(x) and x in COORDINATE and math.hypot(x, 1.0) in LENGTH


M = Lambertian()
API_CASES = [
    ("Sphere center", lambda x: Sphere((0.0, x, 0.0), 1.0, M), ("center",), _inside(COORDINATE)),
    ("Sphere radius", lambda x: Sphere((0.0, 0.0, 0.0), x, M), ("radius",), _inside(LENGTH)),
    ("Quad q", lambda x: Quad((x, 0, 0), (1, 0, 0), (0, 1, 0), M), ("q",), _inside(COORDINATE)),
    (
        "Quad u",
        lambda x: Quad((0, 0, 0), (x, 0, 0), (0, 1, 0), M),
        ("u",),
        lambda x: math.isfinite(x) and abs(x) in LENGTH,
    ),
    (
        "Quad v",
        lambda x: Quad((0, 0, 0), (1, 0, 0), (0, 1, x), M),
        ("v",),
        _vector_length_ok,
    ),
    (
        "Triangle a",
        lambda x: Triangle((0, x, 0), (1, 0, 0), (0, 0, 1), M),
        ("a",),
        _inside(COORDINATE),
    ),
    (
        "Camera look_from",
        lambda x: Camera(look_from=(x, 0, 0), look_at=(0, 0, -1)),
        ("look_from", "look_at"),
        _vector_length_ok,
    ),
    (
        "Camera look_at",
        lambda x: Camera(look_from=(0, 0, 0), look_at=(x, 0, -1)),
        ("look_at",),
        _vector_length_ok,
    ),
    ("Camera vup", lambda x: Camera(vup=(x, 1, 0)), ("vup",), _vector_length_ok),
    ("Camera vfov", lambda x: Camera(vfov=x), ("vfov",), _inside(checks.VFOV)),
    (
        "Camera aspect_ratio",
        lambda x: Camera(aspect_ratio=x, width=1),
        ("aspect_ratio",),
        _inside(checks.ASPECT_RATIO),
    ),
    (
        "Camera defocus_angle",
        lambda x: Camera(defocus_angle=x),
        ("defocus_angle",),
        _inside(checks.DEFOCUS_ANGLE),
    ),
    (
        "Camera focus_distance",
        lambda x: Camera(focus_distance=x),
        ("focus_distance",),
        _inside(LENGTH),
    ),
    (
        "PointLight position",
        lambda x: PointLight((0, 0, x), (1, 1, 1)),
        ("position",),
        _inside(COORDINATE),
    ),
    (
        "PointLight intensity",
        lambda x: PointLight((0, 0, 0), (1, x, 1)),
        ("intensity",),
        _inside(RADIANCE),
    ),
    ("SolidColor color", lambda x: SolidColor((x, 0, 0)), ("color",), _inside(UNIT)),
    ("CheckerTexture scale", lambda x: CheckerTexture(x, GREY, GREY), ("scale",), _inside(LENGTH)),
    ("CheckerTexture odd", lambda x: CheckerTexture(1, GREY, (0, 0, x)), ("odd",), _inside(UNIT)),
    (
        "SkyBand radiance",
        lambda x: SkyBand((x, 0, 0), 0, 90),
        ("radiance",),
        _inside(RADIANCE),
    ),
    ("Scene background", lambda x: Scene(background=(x, 1, 1)), ("background",), _inside(RADIANCE)),
    (
        "Transform translate",
        lambda x: Transform(translate=(0, x, 0)),
        ("translate",),
        _inside(COORDINATE),
    ),
    ("Transform rotate", lambda x: Transform(rotate=(0, 0, x)), ("rotate",), _inside(checks.ANGLE)),
    (
        "Transform scale",
        lambda x: Transform(scale=(x, 1, 1)),
        ("scale",),
        lambda x: math.isfinite(x) and abs(x) in LENGTH,
    ),
    ("RenderSettings gamma", lambda x: RenderSettings(gamma=x), ("gamma",), _inside(checks.GAMMA)),
    *_material_cases(),
]


def check_api_value(build, names, ok, x) -> None:
    """build(x) succeeds exactly when ok(x); otherwise it raises a ValueError whose
    message starts with one of the parameter's names."""
    if ok(x):
        build(x)
        return
    with pytest.raises(ValueError) as info:
        build(x)
    assert str(info.value).split(":")[0] in names, str(info.value)


@pytest.mark.parametrize(
    ("label", "build", "names", "ok"), API_CASES, ids=[c[0] for c in API_CASES]
)
def test_constructors_take_their_ranges_and_refuse_the_rest_naming_the_parameter(
    label, build, names, ok
):
    for x in SPECIAL_FLOATS:
        check_api_value(build, names, ok, x)


@pytest.mark.slow
@pytest.mark.parametrize(
    ("label", "build", "names", "ok"), API_CASES, ids=[c[0] for c in API_CASES]
)
@settings(max_examples=API_EXAMPLES, deadline=None)
@given(x=extreme_floats(signed=True, zero=True, non_finite=True))
def test_constructors_over_every_magnitude(label, build, names, ok, x):
    check_api_value(build, names, ok, x)


@pytest.mark.parametrize(
    "make",
    [
        lambda v: Sphere(v, 0.5, M).center,
        lambda v: PointLight(v, (1, 1, 1)).position,
        lambda v: Camera(look_from=v, look_at=(0, 0, -1)).look_from,
        lambda v: Lambertian(v).albedo.color,
    ],
)
def test_sequences_become_vectors_and_other_types_are_type_errors(make):
    for v in [(0.25, 0.5, 0.75), [0.25, 0.5, 0.75], np.array([0.25, 0.5, 0.75])]:
        made = make(v)
        assert isinstance(made, Vec3) and made.tolist() == [0.25, 0.5, 0.75]
    for v in ["red", 0.5, (0.25, 0.5), (0.25, "0.5", 0.75), np.zeros((3, 1)), None]:
        with pytest.raises(TypeError, match=r"^\w+: expected an array of 3"):
            make(v)


def test_seed_is_an_integer_up_to_2_63_through_render_on_both_backends():
    scene = Scene([Sphere((0, 0, -1), 0.5, M)], camera=Camera(width=4))
    for backend in rtpy.BACKENDS:
        for seed in (-1, 2**63, 1.0):
            with pytest.raises((TypeError, ValueError), match="^seed: "):
                rtpy.render(scene, spp=1, seed=seed, backend=backend)
    assert RenderSettings(seed=2**63 - 1).seed == 2**63 - 1


def test_render_refuses_arguments_of_the_wrong_type():
    scene = Scene([Sphere((0, 0, -1), 0.5, M)], camera=Camera(width=4))
    for kwargs, name in [({"workers": 0}, "workers"), ({"workers": 1.0}, "workers")]:
        with pytest.raises((TypeError, ValueError), match=f"^{name}: "):
            rtpy.render(scene, **kwargs)
    with pytest.raises(TypeError, match="^camera: "):
        rtpy.render(scene, camera="front")
    with pytest.raises(TypeError, match="^scene: "):
        rtpy.render("cornell")
    with pytest.raises(TypeError, match=r"^objects\[0\]: "):
        Scene([(0, 0, -1)])


@pytest.mark.parametrize(
    "text, shown",
    [
        ("plain text, é and 'quotes'", "plain text, é and 'quotes'"),
        ("two\nlines", "two\\nlines"),
        ("a\r\nb\tc", "a\\r\\nb\\tc"),
        ("nul \x00 and \u2028", "nul \\x00 and \\u2028"),
    ],
)
def test_one_line_escapes_what_would_break_or_hide_a_message_line(text, shown):
    assert checks.one_line(text) == shown and len(checks.one_line(text).splitlines()) == 1


def _shapes(material):
    """Each of the course's shapes made with `material`."""
    from rtpy.mesh import Mesh

    o, x, y = rtpy.Vec3(0, 0, 0), rtpy.Vec3(1, 0, 0), rtpy.Vec3(0, 1, 0)
    return {
        "Sphere": lambda: rtpy.Sphere(o, 0.5, material),
        "Quad": lambda: rtpy.Quad(o, x, y, material),
        "Triangle": lambda: rtpy.Triangle(o, x, y, material),
        "Mesh": lambda: Mesh(
            [[0, 0, 0], [1, 0, 0], [0, 1, 0]], [], [[(0, -1), (1, -1), (2, -1)]], material
        ),  # fmt: skip
    }


@pytest.mark.parametrize("shape", ["Sphere", "Quad", "Triangle", "Mesh"])
@pytest.mark.parametrize("material", ["lambertian", None, 3, rtpy.Color(0.5, 0.5, 0.5)])
def test_a_shape_refuses_what_is_not_a_material_naming_material(shape, material):
    with pytest.raises(TypeError, match=r"^material: expected a Material") as caught:
        _shapes(material)[shape]()
    assert "\n" not in str(caught.value)
    made = _shapes(rtpy.Lambertian())[shape]()
    assert isinstance(made.material, rtpy.Lambertian)
