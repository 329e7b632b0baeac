"""Tests for rtpy.io.scene_file (loading and checking scene files) and rtpy.io.bundled."""

from __future__ import annotations

import json
import math
import re
from pathlib import Path

import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st
from PIL import Image

from rtpy.camera import MAX_PIXELS, Camera
from rtpy.io import bundled
from rtpy.io.bundled import bundled_dir, bundled_scenes, resolve_scene
from rtpy.io.scene_file import (
    MAX_HEIGHT,
    MAX_SPP,
    MAX_WIDTH,
    SceneError,
    load_scene,
    load_scene_text,
)
from rtpy.light import PointLight
from rtpy.materials import Dielectric, DiffuseLight, Lambertian, Metal, Mirror
from rtpy.quad import Quad
from rtpy.render_settings import RenderSettings
from rtpy.scene import Scene
from rtpy.sphere import Sphere
from rtpy.texture import CheckerTexture, ImageTexture, SolidColor
from rtpy.triangle import Triangle
from rtpy.vec3 import Color, Vec3

FILE = Path("some/dir/test_scene.toml")
GREY = Color(0.5, 0.5, 0.5)

MINIMAL = """\
[materials.red]
type = "lambertian"
albedo = [0.5, 0.1, 0.1]

[[objects]]
type = "sphere"
center = [0, 0, -1]
radius = 0.5
material = "red"
"""

# Every key of the contract, with non-default values.
FULL = """\
# every key of format 1
[camera]
look_from = [1, 2, 3]
look_at = [0, 0, -1]
vup = [0, 1, 0]
vfov = 40
aspect_ratio = "4:3"
width = 64
defocus_angle = 0.5
focus_distance = 3.5

[render]
integrator = "whitted"
spp = 4
max_depth = 5
nee = false
russian_roulette = 3
seed = 7
background = [0.1, 0.2, 0.3]
sky = true
gamma = 2.2

[textures.plain]
type = "solid"
color = [0.2, 0.3, 0.4]

[textures.board]
type = "checker"
scale = 0.5
even = [0, 0, 0]
odd = [1, 1, 1]

[textures.board_default_scale]
type = "checker"
even = [0.1, 0.1, 0.1]
odd = [0.9, 0.9, 0.9]

[materials.matte]
type = "lambertian"
albedo = "board"

[materials.matte2]
type = "lambertian"
albedo = [0.2, 0.2, 0.2]

[materials.shiny]
type = "mirror"
albedo = [0.9, 0.9, 0.9]

[materials.brushed]
type = "metal"
albedo = "plain"
fuzz = 0.3

[materials.glass]
type = "dielectric"
ior = 1.33
albedo = [1, 1, 1]

[materials.lamp]
type = "diffuse_light"
emit = [4, 4, 4]
two_sided = true

[[objects]]
type = "sphere"
center = [0, 0, -1]
radius = 0.5
material = "matte"

[[objects]]
type = "quad"
q = [-1, -1, -2]
u = [2, 0, 0]
v = [0, 2, 0]
material = "lamp"

[[objects]]
type = "triangle"
a = [0, 0, -3]
b = [1, 0, -3]
c = [0, 1, -3]
material = "glass"

[[lights]]
type = "point"
position = [0, 5, 0]
intensity = [10, 10, 10]
"""


def load(text: str, path: Path = FILE) -> Scene:
    return load_scene_text(text, path)


def error_of(text: str, path: Path = FILE) -> SceneError:
    with pytest.raises(SceneError) as info:
        load_scene_text(text, path)
    return info.value


def assert_names(err: SceneError, table: str, key: str | None, suggestion: str | None = None):
    """The message names the file, the table and the key (and the suggestion)."""
    msg = str(err)
    assert str(FILE) in msg
    assert err.file == str(FILE)
    assert err.table == table
    assert table in msg
    if key is not None:
        assert err.key == key
        assert f"{table} {key}:" in msg
    if suggestion is not None:
        assert err.suggestion == suggestion
        assert f"did you mean '{suggestion}'?" in msg
    # one message, one line
    assert "\n" not in msg


def line_of(text: str, needle: str, occurrence: int = 1) -> int:
    hits = [i + 1 for i, line in enumerate(text.splitlines()) if line.strip().startswith(needle)]
    return hits[occurrence - 1]


# --------------------------------------------------------------------------- defaults


def test_minimal_scene_loads_with_contract_defaults():
    scene = load(MINIMAL)
    assert isinstance(scene, Scene)
    assert scene.name == "test_scene"
    cam = scene.camera
    assert isinstance(cam, Camera)
    assert cam.look_from == Vec3(0, 0, 0)
    assert cam.look_at == Vec3(0, 0, -1)
    assert cam.vup == Vec3(0, 1, 0)
    assert cam.vfov == 90
    assert cam.aspect_ratio == pytest.approx(16 / 9)
    assert cam.width == 400
    assert cam.height == max(1, int(400 / (16 / 9)))
    assert cam.defocus_angle == 0
    assert cam.focus_distance == 10
    assert scene.settings == RenderSettings()
    s = scene.settings
    assert (s.integrator, s.spp, s.max_depth, s.nee, s.russian_roulette, s.seed, s.gamma) == (
        "path",
        16,
        8,
        True,
        5,
        0,
        2.0,
    )
    assert scene.background == Color(0, 0, 0)
    assert scene.sky is False
    assert scene.point_lights == []
    assert len(scene.objects) == 1
    sphere = scene.objects[0]
    assert isinstance(sphere, Sphere)
    assert sphere.center == Vec3(0, 0, -1) and sphere.radius == 0.5
    assert isinstance(sphere.material, Lambertian)
    assert isinstance(sphere.material.albedo, SolidColor)
    assert sphere.material.albedo.color == Color(0.5, 0.1, 0.1)


def test_empty_file_is_an_empty_scene_with_defaults():
    scene = load("")
    assert scene.objects == [] and scene.point_lights == []
    assert scene.settings == RenderSettings()


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


def test_every_key_of_the_contract_is_accepted():
    scene = load(FULL)
    cam = scene.camera
    assert cam.look_from == Vec3(1, 2, 3)
    assert cam.vfov == 40
    assert cam.aspect_ratio == pytest.approx(4 / 3)
    assert (cam.width, cam.height) == (64, 48)
    assert cam.defocus_angle == 0.5 and cam.focus_distance == 3.5
    assert scene.settings == RenderSettings(
        integrator="whitted", spp=4, max_depth=5, nee=False, russian_roulette=3, seed=7, gamma=2.2
    )
    assert scene.background == Color(0.1, 0.2, 0.3)
    assert scene.sky is True
    sphere, quad, tri = scene.objects
    assert isinstance(sphere, Sphere) and isinstance(quad, Quad) and isinstance(tri, Triangle)
    assert isinstance(sphere.material.albedo, CheckerTexture)
    assert sphere.material.albedo.inv_scale == 2.0
    assert isinstance(quad.material, DiffuseLight) and quad.material.two_sided is True
    assert isinstance(tri.material, Dielectric) and tri.material.ior == 1.33
    (light,) = scene.point_lights
    assert isinstance(light, PointLight)
    assert light.position == Vec3(0, 5, 0) and light.intensity == Color(10, 10, 10)


def test_aspect_ratio_string_gives_the_contract_height():
    for text, ratio in (('"16:9"', 16 / 9), ('"16/9"', 16 / 9), ('"4:3"', 4 / 3), ("1.5", 1.5)):
        for width in (400, 401, 123, 1):
            scene = load(f"[camera]\naspect_ratio = {text}\nwidth = {width}\n")
            assert scene.camera.height == max(1, int(width / ratio))
            assert scene.camera.width == width


def test_albedo_naming_a_texture_links_the_texture_object():
    text = """
[textures.tex]
type = "checker"
scale = 2
even = [1, 0, 0]
odd = [0, 0, 1]
[materials.a]
type = "lambertian"
albedo = "tex"
[materials.b]
type = "metal"
albedo = "tex"
[[objects]]
type = "sphere"
center = [0, 0, -1]
radius = 1
material = "a"
[[objects]]
type = "sphere"
center = [0, 0, -4]
radius = 1
material = "b"
"""
    scene = load(text)
    ta, tb = (o.material.albedo for o in scene.objects)
    assert isinstance(ta, CheckerTexture)
    assert ta is tb
    assert ta.even == Color(1, 0, 0) and ta.odd == Color(0, 0, 1)


def test_materials_are_shared_between_objects():
    scene = load(MINIMAL + MINIMAL.split("\n\n", 1)[1])
    assert scene.objects[0].material is scene.objects[1].material


def test_image_texture_path_is_relative_to_the_scene_file(tmp_path):
    (tmp_path / "tex").mkdir()
    Image.new("RGB", (4, 2), (255, 0, 0)).save(tmp_path / "tex" / "red.png")
    scene_file = tmp_path / "s.toml"
    scene_file.write_text(
        '[textures.img]\ntype = "image"\npath = "tex/red.png"\n'
        '[materials.m]\ntype = "lambertian"\nalbedo = "img"\n'
        '[[objects]]\ntype = "sphere"\ncenter = [0, 0, -1]\nradius = 1\nmaterial = "m"\n',
        encoding="utf-8",
    )
    scene = load_scene(scene_file)
    tex = scene.objects[0].material.albedo
    assert isinstance(tex, ImageTexture)
    assert (tex.width, tex.height) == (4, 2)
    assert tex.pixels[0, 0, 0] == pytest.approx(1.0)
    # the same text loaded from elsewhere does not find the image
    err = error_of(scene_file.read_text(encoding="utf-8"), tmp_path / "elsewhere" / "s.toml")
    assert err.key == "path" and str(tmp_path / "elsewhere" / "tex" / "red.png") in str(err)


def test_unused_textures_and_materials_are_allowed():
    scene = load(
        MINIMAL + '[textures.spare]\ntype = "solid"\ncolor = [1, 1, 1]\n'
        '[materials.spare]\ntype = "mirror"\n'
    )
    assert len(scene.objects) == 1


def test_integers_are_accepted_for_floats_and_scene_name_is_the_stem(tmp_path):
    p = tmp_path / "my_scene.toml"
    p.write_text("[camera]\nvfov = 45\nfocus_distance = 2\n[render]\ngamma = 2\n", "utf-8")
    scene = load_scene(p)
    assert scene.name == "my_scene"
    assert scene.camera.vfov == 45.0 and scene.settings.gamma == 2.0


def test_utf8_bom_is_accepted(tmp_path):
    p = tmp_path / "bom.toml"
    p.write_bytes(b"\xef\xbb\xbf" + MINIMAL.encode("utf-8"))
    assert len(load_scene(p).objects) == 1


# --------------------------------------------------------------------------- errors


def test_unknown_table_with_suggestion():
    text = MINIMAL + "\n[camra]\nwidth = 10\n"
    err = error_of(text)
    assert_names(err, "[camra]", None, "camera")
    assert err.line == line_of(text, "[camra]")


def test_unknown_top_level_key():
    err = error_of("widht = 3\n" + MINIMAL)
    assert_names(err, "[widht]", None)
    assert err.line == 1


def test_unknown_key_with_suggestion():
    text = "[camera]\nvfov = 30\nlook_att = [0, 0, 1]\n"
    err = error_of(text)
    assert_names(err, "[camera]", "look_att", "look_at")
    assert err.line == 3
    assert "(line 3)" in str(err)


def test_unknown_key_in_material_uses_constructor_signature():
    err = error_of('[materials.m]\ntype = "metal"\nfuz = 0.1\n')
    assert_names(err, "[materials.m]", "fuz", "fuzz")
    assert "albedo" in str(err) and "fuzz" in str(err)


def test_unknown_key_in_object_and_light():
    err = error_of(MINIMAL + "radiu = 2\n")
    assert_names(err, "[[objects]] #1", "radiu", "radius")
    err = error_of('[[lights]]\ntype = "point"\nposition = [0, 0, 0]\nintensty = [1, 1, 1]\n')
    assert_names(err, "[[lights]] #1", "intensty", "intensity")


def test_wrong_type():
    err = error_of('[camera]\nvfov = "wide"\n')
    assert_names(err, "[camera]", "vfov")
    assert "expected a number" in str(err) and '"wide"' in str(err)
    err = error_of("[camera]\nlook_from = [1, 2]\n")
    assert_names(err, "[camera]", "look_from")
    assert "3" in str(err)
    err = error_of('[render]\nsky = "yes"\n')
    assert_names(err, "[render]", "sky")
    assert "true or false" in str(err)
    err = error_of("[render]\nnee = 1\n")
    assert_names(err, "[render]", "nee")


def test_float_for_integer_key_is_refused_with_a_hint():
    err = error_of("[render]\nspp = 16.0\n")
    assert_names(err, "[render]", "spp")
    assert "integer" in str(err) and "write 16" in str(err)
    err = error_of("[camera]\nwidth = 300.5\n")
    assert_names(err, "[camera]", "width")


def test_bool_is_not_a_number():
    err = error_of("[camera]\nvfov = true\n")
    assert_names(err, "[camera]", "vfov")
    err = error_of("[render]\nspp = true\n")
    assert_names(err, "[render]", "spp")
    err = error_of('[[lights]]\ntype = "point"\nposition = [0, true, 0]\nintensity = [1, 1, 1]\n')
    assert_names(err, "[[lights]] #1", "position")
    assert "booleans are not numbers" in str(err)


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
    assert "> 0" in str(err)


@pytest.mark.parametrize(
    ("text", "table", "key"),
    [
        (
            '[[objects]]\ntype = "sphere"\ncenter = [0, 0, 0]\nmaterial = "m"\n',
            "[[objects]] #1",
            "radius",
        ),
        (
            '[[objects]]\ntype = "quad"\nq = [0, 0, 0]\nu = [1, 0, 0]\nmaterial = "m"\n',
            "[[objects]] #1",
            "v",
        ),
        (
            '[[objects]]\ntype = "triangle"\na = [0, 0, 0]\nb = [1, 0, 0]\nc = [0, 1, 0]\n',
            "[[objects]] #1",
            "material",
        ),
        ("[[objects]]\ncenter = [0, 0, 0]\n", "[[objects]] #1", "type"),
        ("[materials.m]\nalbedo = [1, 1, 1]\n", "[materials.m]", "type"),
        ('[materials.m]\ntype = "diffuse_light"\n', "[materials.m]", "emit"),
        ('[textures.t]\ntype = "solid"\n', "[textures.t]", "color"),
        ('[textures.t]\ntype = "checker"\neven = [0, 0, 0]\n', "[textures.t]", "odd"),
        ('[textures.t]\ntype = "image"\n', "[textures.t]", "path"),
        ('[[lights]]\ntype = "point"\nintensity = [1, 1, 1]\n', "[[lights]] #1", "position"),
        ('[[lights]]\ntype = "point"\nposition = [1, 1, 1]\n', "[[lights]] #1", "intensity"),
    ],
)
def test_missing_required_key(text, table, key):
    err = error_of('[materials.m]\ntype = "lambertian"\n' * ("materials.m" not in text) + text)
    assert_names(err, table, key)
    assert "missing" in str(err)


@pytest.mark.parametrize(
    ("text", "table", "suggestion"),
    [
        (MINIMAL.replace('"sphere"', '"sphear"'), "[[objects]] #1", "sphere"),
        (MINIMAL.replace('"lambertian"', '"lambertain"'), "[materials.red]", "lambertian"),
        ('[textures.t]\ntype = "checkers"\n', "[textures.t]", "checker"),
        ('[[lights]]\ntype = "pont"\n', "[[lights]] #1", "point"),
    ],
)
def test_unknown_type_with_suggestion(text, table, suggestion):
    err = error_of(text)
    assert_names(err, table, "type", suggestion)
    assert "unknown" in str(err)


def test_missing_material_reference_with_suggestion():
    text = MINIMAL.replace('material = "red"', 'material = "rde"')
    err = error_of(text)
    assert_names(err, "[[objects]] #1", "material", "red")
    assert "rde" in str(err)
    assert err.line == line_of(text, "material =")


def test_missing_texture_reference_with_suggestion():
    text = (
        '[textures.marble]\ntype = "solid"\ncolor = [1, 1, 1]\n'
        '[materials.m]\ntype = "lambertian"\nalbedo = "marbel"\n'
    )
    err = error_of(text)
    assert_names(err, "[materials.m]", "albedo", "marble")
    assert err.line == 6


def test_degenerate_quad():
    text = MINIMAL + (
        '[[objects]]\ntype = "quad"\nq = [0, 0, 0]\nu = [1, 1, 0]\nv = [2, 2, 0]\n'
        'material = "red"\n'
    )
    err = error_of(text)
    assert_names(err, "[[objects]] #2", "u")
    assert "degenerate" in str(err)
    assert err.line == line_of(text, "u =")


def test_degenerate_triangle():
    text = MINIMAL + (
        '[[objects]]\ntype = "triangle"\na = [0, 0, 0]\nb = [1, 1, 1]\nc = [2, 2, 2]\n'
        'material = "red"\n'
    )
    err = error_of(text)
    assert_names(err, "[[objects]] #2", "a")
    assert "degenerate" in str(err)


def test_vup_parallel_to_view_direction():
    err = error_of("[camera]\nlook_from = [0, 5, 0]\nlook_at = [0, 0, 0]\nvup = [0, 2, 0]\n")
    assert_names(err, "[camera]", "vup")
    assert "parallel" in str(err)
    assert err.line == 4


def test_look_from_equal_to_look_at():
    err = error_of("[camera]\nlook_from = [1, 1, 1]\nlook_at = [1, 1, 1]\n")
    assert_names(err, "[camera]", "look_at")


@pytest.mark.parametrize(
    "value",
    [
        '"16x9"',
        '"16:"',
        '":9"',
        '"a:b"',
        '"16:0"',
        '"0:9"',
        '"nan:1"',
        '"inf:1"',
        '""',
        "[16, 9]",
        "true",
    ],
)
def test_bad_aspect_ratio(value):
    err = error_of(f"[camera]\naspect_ratio = {value}\n")
    assert_names(err, "[camera]", "aspect_ratio")
    assert '"W:H"' in str(err)


def test_absurd_sizes_are_refused_with_the_limits():
    err = error_of(f"[camera]\nwidth = {MAX_WIDTH + 1}\n")
    assert_names(err, "[camera]", "width")
    assert str(MAX_WIDTH) in str(err)
    err = error_of("[camera]\nwidth = 1000\naspect_ratio = 0.01\n")
    assert_names(err, "[camera]", "aspect_ratio")
    assert str(MAX_HEIGHT) in str(err)
    err = error_of(f"[render]\nspp = {MAX_SPP + 1}\n")
    assert_names(err, "[render]", "spp")
    assert str(MAX_SPP) in str(err)
    err = error_of("[render]\nmax_depth = 100000\n")
    assert_names(err, "[render]", "max_depth")
    err = error_of(f"[camera]\nwidth = {2**70}\n")
    assert_names(err, "[camera]", "width")
    err = error_of(f"[camera]\nwidth = {MAX_WIDTH}\naspect_ratio = 1\n")
    assert_names(err, "[camera]", "width")
    assert f"{MAX_PIXELS:,}" in str(err)
    # the largest allowed sizes still load (nothing is rendered)
    scene = load(f"[camera]\nwidth = {MAX_WIDTH}\naspect_ratio = 8\n[render]\nspp = {MAX_SPP}\n")
    assert scene.camera.width * scene.camera.height == MAX_PIXELS
    scene = load(f"[camera]\nwidth = 2\naspect_ratio = {2 / MAX_HEIGHT}\n")
    assert scene.camera.height == MAX_HEIGHT


def test_missing_image_file(tmp_path):
    scene_path = tmp_path / "s.toml"
    err = error_of('[textures.t]\ntype = "image"\npath = "nope/missing.png"\n', scene_path)
    assert err.file == str(scene_path) and err.table == "[textures.t]" and err.key == "path"
    assert str(tmp_path / "nope" / "missing.png") in str(err)
    assert err.line == 3


def test_unreadable_image_file(tmp_path):
    (tmp_path / "fake.png").write_text("not an image")
    err = error_of('[textures.t]\ntype = "image"\npath = "fake.png"\n', tmp_path / "s.toml")
    assert err.key == "path" and str(tmp_path / "fake.png") in str(err)


def test_toml_syntax_error_with_line_number():
    text = "[camera]\nwidth = 400\nvfov = 40 degrees\n"
    err = error_of(text)
    assert_names(err, "[camera]", "vfov")
    assert err.line == 3
    assert "TOML syntax error" in str(err) and "(line 3)" in str(err)


def test_toml_syntax_error_in_array_of_tables():
    text = MINIMAL + MINIMAL.split("\n\n", 1)[1].replace("radius = 0.5", "radius = 0.5.5")
    err = error_of(text)
    assert_names(err, "[[objects]] #2", "radius")
    assert err.line == line_of(text, "radius = 0.5.5")


def test_toml_duplicate_key_is_a_syntax_error():
    err = error_of("[render]\nspp = 1\nspp = 2\n")
    assert_names(err, "[render]", "spp")
    assert err.line == 3


def test_line_numbers_for_a_semantic_error():
    text = (
        "# comment\n\n[camera]\nwidth = 100\n\n"
        + MINIMAL
        + "\n"
        + MINIMAL.split("\n\n", 1)[1]
        + "\n"
        + MINIMAL.split("\n\n", 1)[1].replace("radius = 0.5", "radius = -2")
    )
    err = error_of(text)
    assert_names(err, "[[objects]] #3", "radius")
    assert err.line == line_of(text, "radius = -2")
    assert f"(line {err.line})" in str(err)


def test_line_number_falls_back_to_the_header_for_missing_keys():
    text = MINIMAL + "\n[materials.x]\n# nothing here\n"
    err = error_of(text)
    assert err.key == "type" and err.line == line_of(text, "[materials.x]")


def test_line_number_for_inline_tables():
    text = "camera = { width = 10, vfov = 400 }\n"
    err = error_of(text)
    assert_names(err, "[camera]", "vfov")
    assert err.line == 1


def test_wrong_table_shapes():
    err = error_of("camera = 5\n")
    assert_names(err, "[camera]", None)
    err = error_of('[objects]\ntype = "sphere"\n')
    assert_names(err, "[[objects]]", None)
    assert "[[objects]]" in str(err)
    err = error_of("[materials]\nred = 3\n")
    assert_names(err, "[materials]", "red")
    err = error_of("objects = [1, 2]\n")
    assert_names(err, "[[objects]] #1", None)


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


def test_missing_file_unreadable_and_not_utf8(tmp_path):
    missing = tmp_path / "missing.toml"
    with pytest.raises(SceneError) as info:
        load_scene(missing)
    assert str(missing) in str(info.value)
    with pytest.raises(SceneError) as info:
        load_scene(tmp_path)
    assert str(tmp_path) in str(info.value)
    latin1 = tmp_path / "latin1.toml"
    latin1.write_bytes(b"# ok\n# caf\xe9\n")
    with pytest.raises(SceneError) as info:
        load_scene(latin1)
    assert str(latin1) in str(info.value) and "UTF-8" in str(info.value)
    assert info.value.line == 2


def test_huge_integer_literal_and_deep_nesting_are_scene_errors():
    with pytest.raises(SceneError):
        load("[render]\nseed = 1" + "0" * 5000 + "\n")
    with pytest.raises(SceneError):
        load("[camera]\nvup = " + "[" * 5000 + "]" * 5000 + "\n")


# --------------------------------------------------------------------------- fuzzing


def toml_value(v) -> str:
    """A TOML literal for a Python value (inline forms only)."""
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, int):
        return str(v)
    if isinstance(v, float):
        if math.isnan(v):
            return "nan"
        if math.isinf(v):
            return "inf" if v > 0 else "-inf"
        return repr(v)
    if isinstance(v, str):
        return json.dumps(v, ensure_ascii=False).replace("\x7f", "\\u007f")
    if isinstance(v, list):
        return "[" + ", ".join(toml_value(x) for x in v) + "]"
    if isinstance(v, dict):
        return "{" + ", ".join(f"{json.dumps(k)} = {toml_value(x)}" for k, x in v.items()) + "}"
    raise TypeError(type(v))


def to_toml(data: dict) -> str:
    lines = []
    for name, value in data.items():
        if isinstance(value, dict) and all(isinstance(x, dict) for x in value.values()) and value:
            for sub, table in value.items():
                lines.append(f"[{json.dumps(name)}.{json.dumps(sub)}]")
                lines += [f"{json.dumps(k)} = {toml_value(x)}" for k, x in table.items()]
        elif isinstance(value, dict):
            lines.append(f"[{json.dumps(name)}]")
            lines += [f"{json.dumps(k)} = {toml_value(x)}" for k, x in value.items()]
        elif isinstance(value, list) and value and all(isinstance(x, dict) for x in value):
            for table in value:
                lines.append(f"[[{json.dumps(name)}]]")
                lines += [f"{json.dumps(k)} = {toml_value(x)}" for k, x in table.items()]
        else:
            lines.insert(0, f"{json.dumps(name)} = {toml_value(value)}")
    return "\n".join(lines) + "\n"


def test_toml_writer_round_trips():
    import tomllib

    data = tomllib.loads(FULL)
    assert tomllib.loads(to_toml(data)) == data
    assert load(to_toml(data)).settings == load(FULL).settings


SCALARS = st.one_of(
    st.booleans(),
    st.integers(min_value=-(2**63), max_value=2**63 - 1),
    st.sampled_from([0, 1, -1, 2, 3, 16384, 16385, 10**6, 10**6 + 1]),
    st.floats(allow_nan=True, allow_infinity=True),
    st.sampled_from([0.0, -0.0, 0.5, 1.0, 1.5, 179.99, 180.0, 1e-300, 1e300]),
    st.text(alphabet=st.characters(codec="utf-8", exclude_categories=("Cs",)), max_size=8),
    st.sampled_from(["16:9", "1:0", "0:1", "path", "sphere", "red", "board", "image", "x"]),
)
VALUES = st.one_of(
    SCALARS,
    st.lists(SCALARS, max_size=4),
    st.lists(
        st.floats(allow_nan=False, allow_infinity=False, min_value=-10, max_value=10),
        min_size=3,
        max_size=3,
    ),
    st.lists(st.sampled_from([0, 1, 0.0, 1.0, 0.5]), min_size=3, max_size=3),
    st.dictionaries(st.sampled_from(["type", "a", "x"]), SCALARS, max_size=2),
)


def _tables(data: dict) -> list[dict]:
    """Every table of a parsed scene, the root included."""
    out = [data]
    for value in data.values():
        if isinstance(value, dict):
            out.append(value)
            out += [t for t in value.values() if isinstance(t, dict)]
        elif isinstance(value, list):
            out += [t for t in value if isinstance(t, dict)]
    return out


@settings(max_examples=300, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_random_perturbations_load_or_raise_scene_error(data):
    import tomllib

    scene = tomllib.loads(FULL.replace('aspect_ratio = "4:3"', "aspect_ratio = 1.25"))
    for _ in range(data.draw(st.integers(min_value=1, max_value=3))):
        tables = _tables(scene)
        table = data.draw(st.sampled_from(tables))
        action = data.draw(st.sampled_from(["replace", "replace", "delete", "add"]))
        if action == "add" or not table:
            key = data.draw(
                st.sampled_from(
                    ["type", "albedo", "radius", "width", "spp", "emit", "material", "zzz", "sky"]
                )
            )
        else:
            key = data.draw(st.sampled_from(sorted(table)))
        if action == "delete":
            table.pop(key, None)
        else:
            table[key] = data.draw(VALUES)
    text = to_toml(scene)
    try:
        tomllib.loads(text)
    except tomllib.TOMLDecodeError:
        pass  # the writer made a file that is not TOML: still must be a SceneError
    try:
        result = load(text)
    except SceneError as e:
        assert str(FILE) in str(e)
        event(f"SceneError {e.key}" if e.key else f"SceneError {e.detail[:40]}")
        return
    event("loaded")
    assert isinstance(result, Scene)
    assert isinstance(result.camera, Camera)
    assert 1 <= result.camera.width <= MAX_WIDTH and 1 <= result.camera.height <= MAX_HEIGHT


@settings(max_examples=200, deadline=None)
@given(text=st.text(alphabet=st.sampled_from(list("[]=\"'.,#\n abc123{}tfe-+:_")), max_size=80))
def test_random_text_loads_or_raises_scene_error(text):
    try:
        load(text)
    except SceneError:
        pass


# --------------------------------------------------------------------------- bundled scenes


def _write_scene(folder: Path, name: str, description: str | None) -> None:
    head = f"# {description}\n" if description is not None else ""
    (folder / f"{name}.toml").write_text(head + MINIMAL, encoding="utf-8")


@pytest.fixture
def fake_bundled(tmp_path, monkeypatch):
    folder = tmp_path / "bundled"
    folder.mkdir()
    _write_scene(folder, "zeta", "Last scene")
    _write_scene(folder, "alpha", "First scene: a sphere")
    _write_scene(folder, "plain", None)
    (folder / "notes.txt").write_text("not a scene")
    monkeypatch.setattr(bundled, "bundled_dir", lambda: folder)
    return folder


def test_bundled_scenes_lists_names_and_descriptions(fake_bundled):
    assert bundled_scenes() == [
        ("alpha", "First scene: a sphere"),
        ("plain", ""),
        ("zeta", "Last scene"),
    ]


def test_resolve_scene(fake_bundled, tmp_path, monkeypatch):
    assert resolve_scene("alpha") == fake_bundled / "alpha.toml"
    assert resolve_scene("alpha.toml") == fake_bundled / "alpha.toml"
    # an existing file wins over a bundled name
    monkeypatch.chdir(tmp_path)
    (tmp_path / "alpha.toml").write_text(MINIMAL, encoding="utf-8")
    assert resolve_scene("alpha.toml") == Path("alpha.toml")
    own = tmp_path / "own.toml"
    own.write_text(MINIMAL, encoding="utf-8")
    assert resolve_scene(str(own)) == own
    with pytest.raises(SceneError) as info:
        resolve_scene("zta")
    msg = str(info.value)
    assert "no scene file 'zta' and no bundled scene of that name" in msg
    assert "bundled: alpha, plain, zeta" in msg
    assert info.value.suggestion == "zeta" and "did you mean 'zeta'?" in msg


def test_bundled_dir_is_the_scenes_folder():
    folder = bundled_dir()
    assert folder.is_dir()
    assert (folder / "__init__.py").exists() or any(folder.glob("*.toml"))


REPO_SCENES = Path(__file__).resolve().parents[2] / "scenes"
BUNDLED_FILES = sorted(REPO_SCENES.glob("*.toml"))


@pytest.mark.skipif(not BUNDLED_FILES, reason="no bundled scenes yet")
def test_real_bundled_scenes_are_listed_with_descriptions():
    names = [name for name, _ in bundled_scenes()]
    assert names == sorted(names)
    if bundled_dir().resolve() == REPO_SCENES:
        assert names == [p.stem for p in BUNDLED_FILES]
    for name, description in bundled_scenes():
        assert description, f"bundled scene {name} has no '# description' first line"
        assert not description.startswith("#")


@pytest.mark.parametrize("path", BUNDLED_FILES, ids=[p.stem for p in BUNDLED_FILES])
def test_every_bundled_scene_loads(path):
    scene = load_scene(path)
    assert scene.objects, f"{path.name} has no objects"
    assert scene.name == path.stem
    assert re.fullmatch(r"#\s*\S.*", path.read_text(encoding="utf-8").splitlines()[0])


def test_mis_key_is_a_boolean_defaulting_to_true():
    assert load("").settings.mis is True
    assert load("[render]\nmis = false\n").settings.mis is False
    err = error_of("[render]\nmis = 0\n")
    assert_names(err, "[render]", "mis")
    assert "true or false" in str(err)
    err = error_of("[render]\nmiss = false\n")
    assert_names(err, "[render]", "miss", "mis")
