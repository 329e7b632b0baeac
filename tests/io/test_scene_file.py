"""Tests for rtpy.io.scene_file (loading and checking scene files) and rtpy.io.bundled."""

from __future__ import annotations

import copy
import math
import os

import numpy as np
import pytest
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st
from PIL import Image

from rtpy import _checks as checks
from rtpy._checks import COORDINATE, LENGTH, RADIANCE, UNIT, Range
from rtpy.camera import MAX_PIXELS, Camera
from rtpy.io.material_params import material_parameters
from rtpy.io.scene_file import (
    MAX_HEIGHT,
    MAX_SPP,
    MAX_WIDTH,
    SceneError,
    load_scene,
)
from rtpy.light import PointLight
from rtpy.materials import MATERIALS, Dielectric, DiffuseLight, Lambertian
from rtpy.materials.ranges import MATERIAL_RANGES
from rtpy.quad import Quad
from rtpy.render_settings import RenderSettings
from rtpy.scene import Scene
from rtpy.sphere import Sphere
from rtpy.texture import CheckerTexture, ImageTexture, SolidColor
from rtpy.triangle import Triangle
from rtpy.vec3 import Color, Vec3

from ..strategies import SPECIAL_FLOATS, extreme_floats
from .scene_text import FILE, MINIMAL, VALUES, assert_names, error_of, line_of, load, to_toml

GREY = Color(0.5, 0.5, 0.5)

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


def test_a_scene_lists_the_files_it_read(tmp_path):
    """Scene.files: the scene file, each image and each OBJ file (what an output
    must not overwrite); a scene built in code reads none."""
    Image.new("RGB", (2, 2)).save(tmp_path / "red.png")
    (tmp_path / "tri.obj").write_text("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3\n")
    scene_file = tmp_path / "s.toml"
    scene_file.write_text(
        '[textures.img]\ntype = "image"\npath = "red.png"\n'
        '[materials.m]\ntype = "lambertian"\nalbedo = "img"\n'
        '[[objects]]\ntype = "mesh"\npath = "tri.obj"\nmaterial = "m"\n',
        encoding="utf-8",
    )
    files = load_scene(scene_file).files
    assert files == (scene_file, tmp_path / "red.png", tmp_path / "tri.obj")
    assert Scene().files == ()


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


def test_toml_writer_round_trips():
    import tomllib

    data = tomllib.loads(FULL)
    assert tomllib.loads(to_toml(data)) == data
    assert load(to_toml(data)).settings == load(FULL).settings


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
@pytest.mark.slow
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


def test_mis_key_is_a_boolean_defaulting_to_true():
    assert load("").settings.mis is True
    assert load("[render]\nmis = false\n").settings.mis is False
    err = error_of("[render]\nmis = 0\n")
    assert_names(err, "[render]", "mis")
    assert "true or false" in str(err)
    err = error_of("[render]\nmiss = false\n")
    assert_names(err, "[render]", "miss", "mis")


# --------------------------------------------------------------------------- meshes

TETRA = """\
v 0 0 0
v 1 0 0
v 0 1 0
v 0 0 1
vn -1 -1 -1
vn 1 0 0
vn 0 1 0
vn 0 0 1
f 1//1 3//3 2//2
f 1 2 4
f 1 4 3
f 2 3 4
"""


def mesh_scene(tmp_path, obj_text: str | None, extra: str = "", name: str = "m.obj") -> str:
    """A scene with one mesh object; writes the OBJ file (if given) next to FILE's name."""
    if obj_text is not None:
        (tmp_path / name).write_text(obj_text)
    return (
        '[materials.m]\ntype = "lambertian"\n\n'
        f'[[objects]]\ntype = "mesh"\npath = "{name}"\nmaterial = "m"\n{extra}'
    )


def load_mesh(tmp_path, obj_text, extra="", name="m.obj"):
    return load(mesh_scene(tmp_path, obj_text, extra, name), tmp_path / "s.toml")


def mesh_error(tmp_path, obj_text, extra="", name="m.obj") -> SceneError:
    return error_of(mesh_scene(tmp_path, obj_text, extra, name), tmp_path / "s.toml")


def test_a_mesh_is_one_object_of_its_triangles_placed_by_scale_rotate_translate(tmp_path):
    from rtpy.mesh import Mesh, SmoothTriangle

    extra = "scale = [2, 1, 1]\nrotate = [0, 0, 90]\ntranslate = [0, 0, -5]\n"
    scene = load_mesh(tmp_path, TETRA, extra)
    (mesh,) = scene.objects
    assert isinstance(mesh, Mesh) and len(mesh) == 4
    assert [type(t) for t in mesh.triangles] == [SmoothTriangle, Triangle, Triangle, Triangle]
    first = mesh[0]
    # b = (1, 0, 0) scaled to (2, 0, 0), turned about z to (0, 2, 0), moved to z = -5
    assert (first.c - Vec3(0, 2, -5)).length() < 1e-12
    assert all(t.material is mesh.material for t in mesh.triangles)
    (uniform,) = load_mesh(tmp_path, TETRA, "scale = 3\n").objects
    assert uniform[3].a == Vec3(3, 0, 0)  # face 2 3 4 starts at (1, 0, 0)


def test_an_emitting_mesh_is_its_triangles_each_a_light(tmp_path):
    lamp = 'type = "diffuse_light"\nemit = [1, 1, 1]'
    text = mesh_scene(tmp_path, TETRA).replace('type = "lambertian"', lamp)
    scene = load(text, tmp_path / "s.toml")
    assert [type(t).__name__ for t in scene.objects] == ["SmoothTriangle"] + ["Triangle"] * 3
    assert [light.shape for light in scene.area_lights] == scene.objects


@pytest.mark.parametrize(
    "obj_text, extra, key, words",
    [
        (None, "", "path", "OBJ file not found"),
        ("v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 3 x\n", "", "path", "m.obj line 4: expected an integer"),
        ("v 0 0 0\n", "", "path", "empty mesh"),
        ("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n", "", "path", "all 1 faces are degenerate"),
        (TETRA, "scale = 0\n", "scale", "of size >= 1e-06, found [0, 0, 0]"),
        (TETRA, "scale = [1, 0, 1]\n", "scale", "(component 2 is 0.0)"),
        (TETRA, 'scale = "big"\n', "scale", "expected a number or an array of 3 numbers"),
        (TETRA, "rotate = [0, 90]\n", "rotate", "expected"),
        (TETRA, "translate = 1\n", "translate", "expected"),
        (TETRA, "rotation = [0, 0, 0]\n", "rotation", "unknown key"),
    ],
)
def test_mesh_errors_name_the_file_table_and_key(tmp_path, obj_text, extra, key, words):
    err = mesh_error(tmp_path, obj_text, extra)
    msg = str(err)
    assert err.file == str(tmp_path / "s.toml") and err.table == "[[objects]] #1"
    assert err.key == key and f"[[objects]] #1 {key}:" in msg
    assert words in msg and len(msg.splitlines()) == 1


def test_a_mesh_path_must_be_a_file(tmp_path):
    (tmp_path / "d.obj").mkdir()
    assert "is a directory" in str(mesh_error(tmp_path, None, name="d.obj"))
    err = error_of(mesh_scene(tmp_path, None).replace('path = "m.obj"\n', ""), tmp_path / "s.toml")
    assert err.key == "path" and "missing required key" in str(err)


TETRA_PLY = """\
ply
format ascii 1.0
element vertex 4
property double x
property double y
property double z
element face 4
property list uchar int vertex_indices
end_header
0 0 0
1 0 0
0 1 0
0 0 1
3 0 2 1
3 0 1 3
3 0 3 2
3 1 2 3
"""


def test_a_ply_mesh_is_read_as_the_same_obj_mesh_is(tmp_path):
    flat = TETRA.replace("f 1//1 3//3 2//2", "f 1 3 2")
    (obj,) = load_mesh(tmp_path, flat, "scale = 2\n").objects
    (ply,) = load_mesh(tmp_path, TETRA_PLY, "scale = 2\n", name="m.PLY").objects
    assert np.array_equal(ply.vertices, obj.vertices) and np.array_equal(ply.faces, obj.faces)
    assert np.array_equal(ply.tree.lo, obj.tree.lo)


@pytest.mark.parametrize(
    "text, words",
    [
        (None, "PLY file not found"),
        (TETRA_PLY.replace("3 1 2 3", "3 1 2 4"), "m.ply line 17: face 4: vertex index 4"),
        (TETRA_PLY.replace("format ascii", "format text"), "m.ply line 2: unknown format"),
    ],
)
def test_ply_errors_name_the_file_and_line(tmp_path, text, words):
    err = mesh_error(tmp_path, text, name="m.ply")
    assert err.key == "path" and words in str(err) and len(str(err).splitlines()) == 1


@pytest.mark.parametrize(
    "body, words",
    [
        ("nan 0 0", "m.ply line 10: vertex 1: expected finite numbers for x, y, z, found nan"),
        ("0 0 inf", "m.ply line 10: vertex 1: expected finite numbers for x, y, z, found 0.0"),
    ],
)
def test_a_ply_vertex_that_is_not_finite_is_blamed_on_the_file_not_scale(tmp_path, body, words):
    err = mesh_error(tmp_path, TETRA_PLY.replace("0 0 0\n1 0 0", f"{body}\n1 0 0"), name="m.ply")
    assert err.key == "path" and words in str(err), str(err)


def test_a_huge_binary_list_count_is_blamed_on_the_file_not_scale(tmp_path):
    import struct

    header = TETRA_PLY.split("end_header")[0].replace("ascii", "binary_little_endian")
    header = header.replace("double", "float").replace("uchar", "uint") + "end_header\n"
    vertices = struct.pack("<12f", 0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1)
    faces = struct.pack("<I3i", 4_000_000_000, 0, 2, 1) + struct.pack("<I3i", 3, 0, 1, 3) * 3
    (tmp_path / "m.ply").write_bytes(header.encode() + vertices + faces)
    err = mesh_error(tmp_path, None, name="m.ply")
    assert err.key == "path" and "m.ply: the file ends inside face record 1" in str(err), str(err)


special_files = pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="no FIFOs here")


@special_files
@pytest.mark.parametrize("name", ["m.obj", "m.ply"])
def test_a_mesh_path_that_is_a_fifo_is_refused_at_once(tmp_path, name):
    os.mkfifo(tmp_path / name)  # no writer: a reader that opens it waits forever
    err = mesh_error(tmp_path, None, name=name)
    assert err.key == "path" and "FIFO (named pipe), not a regular file" in str(err), str(err)


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="no /dev/zero")
def test_a_mesh_path_that_is_an_endless_device_is_refused_without_reading(tmp_path):
    err = error_of(mesh_scene(tmp_path, None).replace("m.obj", "/dev/zero"), tmp_path / "s.toml")
    assert err.key == "path" and "character device, not a regular file" in str(err), str(err)


def test_degenerate_faces_are_skipped_and_counted_in_one_warning(tmp_path):
    from rtpy.io.scene_file import SceneWarning

    text = TETRA + "v 2 0 0\nf 1 2 5\nf 2 5 1\n"  # two faces on one line
    with pytest.warns(SceneWarning) as record:
        scene = load_mesh(tmp_path, text)
    assert len(scene.objects[0]) == 4 and scene.objects[0].skipped == 2 and len(record) == 1
    (message,) = str(record[0].message).splitlines()
    assert message.startswith(f"{tmp_path / 's.toml'}: [[objects]] #1 path: skipped 2 degenerate")


# --- every numeric key over every magnitude ---------------------------------------------------


def _inside(rng: Range):
    return lambda x: math.isfinite(x) and x in rng


def _size_inside(rng: Range):
    return lambda x: math.isfinite(x) and abs(x) in rng


def _offset_ok(x: float) -> bool:
    """x as one component of a point 1 away from another: both in range, and apart by a length."""
    return math.isfinite(x) and x in COORDINATE and math.hypot(x, 1.0) in LENGTH


GREY = [0.5, 0.5, 0.5]
KEY_SCENE = {
    "camera": {"look_from": [0, 0, 0], "look_at": [0, 0, -1], "vup": [0, 1, 0], "width": 4},
    "render": {"background": [0, 0, 0]},
    "textures": {"t": {"type": "checker", "scale": 1, "even": GREY, "odd": GREY}},
    "materials": {"m": {"type": "lambertian"}},
    "objects": [
        {"type": "sphere", "center": [0, 0, -1], "radius": 0.5, "material": "m"},
        {"type": "quad", "q": [0, 0, -2], "u": [1, 0, 0], "v": [0, 1, 0], "material": "m"},
        {"type": "triangle", "a": [0, 0, -3], "b": [1, 0, -3], "c": [0, 1, -3], "material": "m"},
        {"type": "mesh", "path": "tetra.obj", "material": "m"},
    ],
    "lights": [{"type": "point", "position": [0, 1, 0], "intensity": [1, 1, 1]}],
}


def _key_cases() -> list[tuple]:
    """(label, table path, key, component or None, x accepted?, keys its errors may name)
    for every number and one component of every array of numbers of KEY_SCENE's tables,
    and every number and colour parameter of every material."""
    cam, obj = ("camera",), ("objects",)
    cases = [
        (cam, "look_from", 0, _offset_ok, ("look_from", "look_at")),
        (cam, "look_at", 0, _offset_ok, ("look_at",)),
        (cam, "vup", 0, _offset_ok, ("vup",)),
        (cam, "vfov", None, _inside(checks.VFOV), ()),
        (
            cam,
            "aspect_ratio",
            None,
            lambda x: _inside(checks.ASPECT_RATIO)(x) and 4 / x < MAX_HEIGHT + 1,
            (),
        ),
        (cam, "defocus_angle", None, _inside(checks.DEFOCUS_ANGLE), ()),
        (cam, "focus_distance", None, _inside(LENGTH), ()),
        (("render",), "gamma", None, _inside(checks.GAMMA), ()),
        (("render",), "background", 1, _inside(RADIANCE), ()),
        (("textures", "t"), "scale", None, _inside(LENGTH), ()),
        (("textures", "t"), "odd", 2, _inside(UNIT), ()),
        ((*obj, 0), "center", 1, _inside(COORDINATE), ()),
        ((*obj, 0), "radius", None, _inside(LENGTH), ()),
        ((*obj, 1), "q", 0, _inside(COORDINATE), ()),
        ((*obj, 1), "u", 0, _size_inside(LENGTH), ()),
        ((*obj, 1), "v", 2, _offset_ok, ()),
        ((*obj, 2), "a", 2, _inside(COORDINATE), ()),
        ((*obj, 3), "translate", 1, lambda x: _inside(COORDINATE)(x) and x + 1 in COORDINATE, ()),
        ((*obj, 3), "rotate", 2, _inside(checks.ANGLE), ()),
        ((*obj, 3), "scale", None, _size_inside(LENGTH), ()),
        (("lights", 0), "position", 2, _inside(COORDINATE), ()),
        (("lights", 0), "intensity", 0, _inside(RADIANCE), ()),
    ]
    for kind, cls in MATERIALS.items():
        for p in material_parameters(cls).values():
            rng = MATERIAL_RANGES.get(p.name)
            if rng is not None and p.kind in ("float", "color", "albedo"):
                component = None if p.kind == "float" else 1
                cases.append((("materials", kind), p.name, component, _inside(rng), ()))
    return [
        (f"{'.'.join(map(str, path))} {key}", path, key, component, ok, (key, *also))
        for path, key, component, ok, also in cases
    ]


KEY_CASES = _key_cases()
# Examples per key in the slow tier (log-uniform magnitudes and special values), on
# top of SPECIAL_FLOATS in the fast tier.
KEY_EXAMPLES = 12


@pytest.fixture(scope="module")
def key_scene_dir(tmp_path_factory):
    path = tmp_path_factory.mktemp("keys")
    (path / "tetra.obj").write_text(TETRA)
    return path


def check_key_value(directory, path, key, component, ok, names, x) -> None:
    """The scene with x at the key loads exactly when ok(x), else its SceneError names
    the file, the table and the key, on one line."""
    data = copy.deepcopy(KEY_SCENE)
    if path[0] == "materials":
        kind = path[1]
        m = {"type": kind, "emit": [1, 1, 1]} if kind == "diffuse_light" else {"type": kind}
        data["materials"] = {"m": m}
        path = ("materials", "m")
    table = data
    for step in path:
        table = table[step]
    if component is None:
        table[key] = x
    else:
        table[key] = list(table.get(key, [0.5, 0.5, 0.5]))
        table[key][component] = x
    file = directory / "keys.toml"
    if ok(x):
        load(to_toml(data), file)
        return
    with pytest.raises(SceneError) as info:
        load(to_toml(data), file)
    err = info.value
    if len(path) == 2 and isinstance(path[1], int):
        label = f"[[{path[0]}]] #{path[1] + 1}"
    else:
        label = f"[{'.'.join(path)}]"
    assert err.file == str(file) and err.table == label and err.key in names, str(err)
    assert f"{label} {err.key}:" in str(err) and "\n" not in str(err)
    assert f"{err.key}: {err.key}:" not in str(err)  # the key is named once


@pytest.mark.parametrize(
    ("camera", "key", "words"),
    [
        ("look_at = [0, 0, 0]", "look_at", "expected a distance from look_from in [1e-06, "),
        ("vup = [0, 0, 2]", "vup", "expected an up vector across the view direction"),
    ],
)
def test_a_camera_that_sees_nothing_is_refused_naming_the_key_once(camera, key, words):
    err = error_of(f"[camera]\n{camera}\n")
    assert_names(err, "[camera]", key)
    assert f"[camera] {key}: {words}" in str(err)


@pytest.mark.parametrize(
    ("label", "path", "key", "component", "ok", "names"), KEY_CASES, ids=[c[0] for c in KEY_CASES]
)
def test_every_key_takes_its_range_and_refuses_the_rest(
    key_scene_dir, label, path, key, component, ok, names
):
    for x in SPECIAL_FLOATS:
        check_key_value(key_scene_dir, path, key, component, ok, names, x)


@pytest.mark.slow
@pytest.mark.parametrize(
    ("label", "path", "key", "component", "ok", "names"), KEY_CASES, ids=[c[0] for c in KEY_CASES]
)
@settings(max_examples=KEY_EXAMPLES, deadline=None)
@given(x=extreme_floats(signed=True, zero=True, non_finite=True))
def test_every_key_over_every_magnitude(key_scene_dir, label, path, key, component, ok, names, x):
    check_key_value(key_scene_dir, path, key, component, ok, names, x)


@special_files
def test_a_scene_or_texture_that_is_a_fifo_is_refused_at_once(tmp_path):
    os.mkfifo(tmp_path / "pipe.png")
    err = error_of('[textures.t]\ntype = "image"\npath = "pipe.png"\n', tmp_path / "s.toml")
    assert err.key == "path" and "FIFO (named pipe), not a regular file" in str(err), str(err)
    os.mkfifo(tmp_path / "scene.toml")
    with pytest.raises(SceneError, match="FIFO"):
        load_scene(tmp_path / "scene.toml")


def test_files_beyond_their_limit_are_refused_before_they_are_read(tmp_path, monkeypatch):
    from rtpy.io import obj, scene_file

    monkeypatch.setattr(obj, "MAX_MESH_BYTES", 100)
    monkeypatch.setattr("rtpy.io.ply.MAX_MESH_BYTES", 100)
    for name, text in (("m.obj", TETRA), ("m.ply", TETRA_PLY)):
        err = mesh_error(tmp_path, text, name=name)
        assert err.key == "path" and "the most read is 100" in str(err), str(err)
    monkeypatch.setattr(scene_file, "MAX_TEXTURE_BYTES", 10)
    Image.new("RGB", (4, 4)).save(tmp_path / "t.png")
    err = error_of('[textures.t]\ntype = "image"\npath = "t.png"\n', tmp_path / "s.toml")
    assert err.key == "path" and "the most read is 10" in str(err), str(err)
