"""Scenes whose every number lies anywhere in its allowed range, however extreme,
render finite, non-negative pixels on both backends with every integrator.

The ranges are the scene-format contract:
- coordinates of points: each component in [-1e6, 1e6], subnormals and 0 included;
- lengths (radius, |quad u|, |quad v|, focus distance, |look_at - look_from|,
  checker scale, mesh scale): [1e-6, 1e6]; |u x v| of a quad and twice a triangle's
  area >= 1e-12;
- |vup| >= 1e-6 and the sine of its angle to the view direction >= 1e-6; vfov in
  [1e-3, 179] degrees, defocus_angle in [0, 179];
- reflectances (albedo, kd, ks, f0) in [0, 1]; radiances (emit, background, point
  intensity) in [0, 1e9]; exponent in [0, 1e6]; roughness and alpha in [1e-4, 1]
  (the most Cook-Torrance and Ward accept); ior in [1e-2, 100]; fuzz in [0, 1e6].

`scene_files()` draws a parsed scene file with each number log-uniform in its range
(tests/strategies.py's extreme_floats, the ends drawn often), with objects and point
lights placed at extreme distances from the eye, from the point looked at and from each
other. The properties render it tiny (4x4 pixels, 1-2 samples, depth <= 4), loaded from
its TOML text and built through the Python API, with every integrator on both
backends. A render may be black or show acne at these scales; it may not give NaN, Inf,
a negative value or an exception. The explicit cases below are the issue's examples
moved to the ends of the ranges.
"""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from hypothesis import HealthCheck, find, given, settings
from hypothesis import strategies as st

import rtpy
from rtpy import (
    Camera,
    CheckerTexture,
    Color,
    CookTorrance,
    Dielectric,
    DiffuseLight,
    Lambertian,
    Metal,
    PointLight,
    Quad,
    Scene,
    SolidColor,
    Sphere,
    Texture,
    Transform,
    Triangle,
    Vec3,
)
from rtpy.io.scene_file import load_scene_text
from rtpy.materials import MATERIALS, BlinnPhong, Phong, RoughDielectric, Ward
from rtpy.render_settings import INTEGRATOR_NAMES
from tests.io.scene_text import to_toml
from tests.io.test_scene_file import TETRA
from tests.strategies import SMALLEST, extreme_floats

from .scene_strategies import add, cross, norm
from .test_fuzz_scenes import bad_pixels

MAX_COORD = 1e6
COORD = extreme_floats(SMALLEST, MAX_COORD, signed=True, zero=True)
LENGTH = extreme_floats(1e-6, 1e6)
REFLECTANCE = extreme_floats(SMALLEST, 1.0, zero=True)
RADIANCE = extreme_floats(SMALLEST, 1e9, zero=True)
UP_TO_1E6 = extreme_floats(SMALLEST, 1e6, zero=True)  # exponent, fuzz
ROUGHNESS = extreme_floats(1e-4, 1.0)
IOR = extreme_floats(1e-2, 100.0)
VFOV = extreme_floats(1e-3, 179.0)
DEFOCUS = extreme_floats(SMALLEST, 179.0, zero=True)
ASPECT = extreme_floats(0.5, 4.0)  # 4 pixels wide, 1 to 8 high
# Distances from an anchor to a light or an object's corner: every magnitude.
SPAN = extreme_floats(SMALLEST, 2.0 * MAX_COORD)


@settings(max_examples=50)
@given(COORD, LENGTH)
def test_extreme_floats_stay_in_their_ranges(coordinate, length):
    assert -MAX_COORD <= coordinate <= MAX_COORD and 1e-6 <= length <= 1e6


@pytest.mark.parametrize(
    "wanted",
    [
        lambda x: 0.0 < abs(x) < 2.2e-308,
        lambda x: 1e-200 < -x < 1e-100,
        lambda x: x == -MAX_COORD,
        lambda x: math.copysign(1.0, x) < 0.0 and x == 0.0,
    ],
    ids=["subnormal", "negative 1e-150", "the end -1e6", "-0.0"],
)
def test_extreme_floats_reach_every_magnitude(wanted):
    find(COORD, wanted, settings=settings(database=None))


def triple(values: st.SearchStrategy[float]) -> st.SearchStrategy[list[float]]:
    return st.lists(values, min_size=3, max_size=3)


@st.composite
def directions(draw) -> list[float]:
    """A unit vector, its components of any magnitude (axis-aligned to within 1e-300)."""
    v = draw(triple(extreme_floats(SMALLEST, 1.0, signed=True, zero=True)))
    length = norm(v)
    return [x / length for x in v] if length > 1e-3 else [0.0, 0.0, -1.0]


def across(v: list[float]) -> list[float]:
    """A unit vector perpendicular to v."""
    axis = [0.0, 0.0, 0.0]
    axis[min(range(3), key=lambda i: abs(v[i]))] = 1.0  # the axis most across v
    w = cross(v, axis)
    return scaled(w, 1.0 / norm(w))


def offset(p: list[float], v: list[float]) -> list[float]:
    """p + v, each component of v turned toward 0 (and shortened to reach at most the
    range's far end) where p + v would leave the range."""
    out = []
    for a, b in zip(p, v, strict=True):
        inward = math.copysign(min(abs(b), MAX_COORD + abs(a)), a)
        c = a + b if abs(a + b) <= MAX_COORD else a - inward
        out.append(min(max(c, -MAX_COORD), MAX_COORD))  # a - inward may round past the end
    return out


def scaled(v: list[float], s: float) -> list[float]:
    return [x * s for x in v]


@st.composite
def cameras(draw) -> dict:
    look_from = draw(triple(COORD))
    view, distance = draw(directions()), draw(LENGTH)
    look_at = offset(look_from, scaled(view, distance))
    while not 1e-6 <= norm(add(look_at, look_from, -1.0)) <= 1e6:  # rounded out of range
        distance *= 1.5 if distance < 1.0 else 1.0 - 1e-9
        look_at = offset(look_from, scaled(view, distance))
    view = add(look_at, look_from, -1.0)
    vup, up_length = draw(directions()), draw(LENGTH)
    while not 1e-6 <= norm(scaled(vup, up_length)) <= 1e6:  # rounded out of range
        up_length *= 1.5 if up_length < 1.0 else 1.0 - 1e-9
    vup = scaled(vup, up_length)
    if not norm(cross(vup, view)) >= 2e-6 * norm(vup) * norm(view):
        vup = across(view)
    camera = {"look_from": look_from, "look_at": look_at, "vup": vup, "vfov": draw(VFOV)}
    camera |= {"aspect_ratio": draw(ASPECT), "width": 4}
    if draw(st.booleans()):
        camera |= {"defocus_angle": draw(DEFOCUS), "focus_distance": draw(LENGTH)}
    return camera


@st.composite
def materials(draw, textures: list[str]) -> dict:
    """A material of any registered kind, every parameter given, at its extremes."""
    kind = draw(st.sampled_from(sorted(MATERIALS)))
    colour = triple(REFLECTANCE)
    albedo = st.sampled_from(textures) | colour if textures else colour
    if kind == "diffuse_light":
        return {"type": kind, "emit": draw(triple(RADIANCE)), "two_sided": draw(st.booleans())}
    if kind in ("dielectric", "rough_dielectric"):
        table = {"type": kind, "ior": draw(IOR)}
        if kind == "rough_dielectric":
            table |= {"roughness": draw(ROUGHNESS), "tint": draw(colour)}
            table["distribution"] = draw(st.sampled_from(["ggx", "beckmann"]))
        return table
    table = {"type": kind, "albedo": draw(albedo)}
    if kind == "metal":
        table["fuzz"] = draw(UP_TO_1E6)
    if kind == "oren_nayar":
        table["sigma"] = draw(st.floats(0.0, 89.99))
    if kind in ("phong", "blinn_phong", "cook_torrance", "ward"):
        table |= {"kd": draw(REFLECTANCE), "ks": draw(REFLECTANCE)}
    if kind in ("phong", "blinn_phong"):
        table["exponent"] = draw(UP_TO_1E6)
    if kind == "cook_torrance":
        table |= {"roughness": draw(ROUGHNESS), "ior": draw(IOR)}
        table["distribution"] = draw(st.sampled_from(["ggx", "beckmann"]))
        if draw(st.booleans()):
            table["f0"] = draw(colour)
    if kind == "ward":
        table |= {"alpha_x": draw(ROUGHNESS), "alpha_y": draw(ROUGHNESS)}
    return table


def fit_edges(q: list[float], edges: list[list[float]]) -> tuple[list[float], list[list[float]]]:
    """q moved toward 0 (and the edges halved when they span more than the range) so
    that every corner q + (a sum of edges) stays inside [-1e6, 1e6]."""
    while any(sum(abs(e[i]) for e in edges) > MAX_COORD for i in range(3)):
        edges = [scaled(e, 0.5) for e in edges]
    lo = [-MAX_COORD + sum(-min(e[i], 0.0) for e in edges) for i in range(3)]
    hi = [MAX_COORD - sum(max(e[i], 0.0) for e in edges) for i in range(3)]
    return [min(hi[i], max(lo[i], q[i])) for i in range(3)], edges


# The mesh the scenes place is TETRA, a tetrahedron in the unit cube with one face
# smooth-shaded. Scaled by at most this per axis and turned any way, its vertices lie
# within sqrt(3) * 5e5 of the translate.
MESH_SCALE = 5e5


@st.composite
def meshes(draw, at: list[float], material: str) -> dict:
    """The tetrahedron scaled by [1e-6, 5e5] on each axis, mirrored or not, turned any
    way, with its corner moved to `at` (toward 0 where the mesh would leave the range)."""
    signed_scale = extreme_floats(1e-6, MESH_SCALE, signed=True)
    scale = [draw(signed_scale) for _ in range(3)]
    rotate = draw(triple(st.floats(-360.0, 360.0)))
    room = MAX_COORD - math.sqrt(3.0) * max(abs(x) for x in scale)
    translate = [min(room, max(-room, x)) for x in at]
    table = {"type": "mesh", "path": "tetrahedron.obj", "material": material}
    return table | {"translate": translate, "rotate": rotate, "scale": scale}


@st.composite
def shapes(draw, anchor: list[float], material: str) -> dict:
    """A sphere, quad, triangle or mesh at (or at any distance from) the anchor."""
    at = offset(anchor, scaled(draw(directions()), draw(SPAN))) if draw(st.booleans()) else anchor
    kind = draw(st.sampled_from(["sphere", "quad", "triangle", "mesh"]))
    if kind == "mesh":
        return draw(meshes(at, material))
    if kind != "sphere":
        du, dv = draw(directions()), draw(directions())
        if not norm(cross(du, dv)) > 1e-3:  # parallel, as extreme directions often are
            dv = across(du)
        edges = [scaled(du, draw(LENGTH)), scaled(dv, draw(LENGTH))]
        q, (u, v) = fit_edges(at, edges)
        lengths = (norm(u), norm(v))  # a unit direction times 1e6 may round past 1e6
        if (
            kind == "quad"
            and norm(cross(u, v)) >= 2e-12
            and 1e-6 <= min(lengths) <= max(lengths) <= 1e6
        ):
            return {"type": "quad", "q": q, "u": u, "v": v, "material": material}
        a, b, c = q, add(q, u), add(q, v)
        if norm(cross(add(b, a, -1.0), add(c, a, -1.0))) >= 2e-12:
            return {"type": "triangle", "a": a, "b": b, "c": c, "material": material}
    return {"type": "sphere", "center": at, "radius": draw(LENGTH), "material": material}


@st.composite
def scene_files(draw) -> dict:
    """A parsed scene file with every number at the extremes of its range."""
    camera = draw(cameras())
    anchors = [camera["look_from"], camera["look_at"], draw(triple(COORD))]
    textures = {"plain": {"type": "solid", "color": draw(triple(REFLECTANCE))}}
    if draw(st.booleans()):
        even, odd = draw(triple(REFLECTANCE)), draw(triple(REFLECTANCE))
        textures["board"] = {"type": "checker", "scale": draw(LENGTH), "even": even, "odd": odd}
    n = draw(st.integers(1, 3))
    mats = {f"m{i}": draw(materials(sorted(textures))) for i in range(n)}
    objects = [draw(shapes(draw(st.sampled_from(anchors)), f"m{i}")) for i in range(n)]
    lights = []
    for _ in range(draw(st.integers(0, 2))):
        near = offset(draw(st.sampled_from(anchors)), scaled(draw(directions()), draw(SPAN)))
        lights.append({"type": "point", "position": near, "intensity": draw(triple(RADIANCE))})
    render = {
        "spp": draw(st.integers(1, 2)),
        "max_depth": draw(st.integers(1, 4)),
        "nee": draw(st.booleans()),
        "mis": draw(st.booleans()),
        "russian_roulette": draw(st.integers(0, 2)),
        "seed": draw(st.integers(0, 2**16)),
    }
    render |= {"sky": True} if draw(st.booleans()) else {"background": draw(triple(RADIANCE))}
    data = {"camera": camera, "render": render, "materials": mats, "objects": objects}
    data["textures"] = textures
    if lights:
        data["lights"] = lights
    return data


def texture(table: dict) -> Texture:
    if table["type"] == "solid":
        return SolidColor(Color(*table["color"]))
    return CheckerTexture(table["scale"], Color(*table["even"]), Color(*table["odd"]))


def shape(table: dict, material, folder: Path) -> list:
    """The objects of an [[objects]] table, built through the Python API."""
    V = Vec3
    if table["type"] == "sphere":
        return [Sphere(V(*table["center"]), table["radius"], material)]
    if table["type"] == "quad":
        return [Quad(V(*table["q"]), V(*table["u"]), V(*table["v"]), material)]
    if table["type"] == "triangle":
        return [Triangle(V(*table["a"]), V(*table["b"]), V(*table["c"]), material)]
    place = Transform(*(V(*table[k]) for k in ("translate", "rotate", "scale")))
    return rtpy.mesh_from_obj(folder / table["path"], material, place).triangles


def build(data: dict, folder: Path) -> Scene:
    """The scene of a parsed scene file, built through the Python API."""
    V = Vec3

    def value(x):
        if isinstance(x, str) and x in textures:
            return textures[x]
        return Color(*x) if isinstance(x, list) else x

    textures = {name: texture(t) for name, t in data["textures"].items()}
    mats = {
        name: MATERIALS[t["type"]](**{k: value(x) for k, x in t.items() if k != "type"})
        for name, t in data["materials"].items()
    }
    objects = [x for o in data["objects"] for x in shape(o, mats[o["material"]], folder)]
    lights = [PointLight(V(*p["position"]), Color(*p["intensity"])) for p in data.get("lights", [])]
    c = data["camera"]
    camera = Camera(
        V(*c["look_from"]), V(*c["look_at"]), V(*c["vup"]), c["vfov"], c["aspect_ratio"],
        c["width"], c.get("defocus_angle", 0.0), c.get("focus_distance", 10.0),
    )  # fmt: skip
    r = data["render"]
    background = Color(*r.get("background", [0.0, 0.0, 0.0]))
    settings_ = rtpy.RenderSettings(
        **{k: v for k, v in r.items() if k not in ("sky", "background")}
    )
    return Scene(objects, lights, background, r.get("sky", False), camera, settings_)


def assert_renders_finite(scene: Scene, what: str) -> None:
    """Every integrator on both backends: finite pixels >= 0."""
    for integrator in INTEGRATOR_NAMES:
        for backend in rtpy.BACKENDS:
            image = rtpy.render(scene, backend=backend, integrator=integrator).linear
            problem = bad_pixels(image)
            assert not problem, f"{backend}, {integrator}: {problem}\n{what}"


def extreme(examples: int) -> settings:
    """examples scenes; each renders ten times, so hypothesis finds them slow."""
    return settings(
        max_examples=examples,
        suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
    )


def check_scene_file(data: dict, folder: Path) -> None:
    text = to_toml(data)
    assert_renders_finite(load_scene_text(text, folder / "extreme.toml"), text)


def check_python_api(data: dict, folder: Path) -> None:
    assert_renders_finite(build(data, folder), repr(data))


@pytest.fixture(scope="module")
def folder(tmp_path_factory) -> Path:
    """Where the scenes are: the tetrahedron's OBJ file is there."""
    path = tmp_path_factory.mktemp("extreme")
    (path / "tetrahedron.obj").write_text(TETRA)
    return path


@extreme(10)
@given(data=scene_files())
def test_extreme_scene_files_render_finite_pixels(folder, data):
    check_scene_file(data, folder)


@extreme(10)
@given(data=scene_files())
def test_extreme_scenes_built_in_python_render_finite_pixels(folder, data):
    check_python_api(data, folder)


@pytest.mark.slow
@extreme(120)
@given(data=scene_files())
def test_more_extreme_scene_files_render_finite_pixels(folder, data):
    check_scene_file(data, folder)


@pytest.mark.slow
@extreme(120)
@given(data=scene_files())
def test_more_extreme_scenes_built_in_python_render_finite_pixels(folder, data):
    check_python_api(data, folder)


# --- the issue's examples, moved to the ends of the ranges -----------------------
V = Vec3
GREY = Lambertian(Color(0.5, 0.5, 0.5))
BRIGHTEST = Color(1e9, 1e9, 1e9)
LAMP = DiffuseLight(BRIGHTEST, two_sided=True)


def floor(material, y: float = -1.0) -> Quad:
    """The largest square quad: edges of 1e6, centred under the eye."""
    return Quad(V(-5e5, y, -5e5), V(1e6, 0, 0), V(0, 0, 1e6), material)


ORIGIN, AHEAD = V(0, 0, 0), V(0, 0, -1)


def eye(look_from: Vec3 = ORIGIN, look_at: Vec3 = AHEAD, **lens) -> Camera:
    return Camera(look_from, look_at, V(0, 1, 0), aspect_ratio=1.0, width=4, **lens)


def lit(objects, point_lights=(), camera=None, **scene) -> Scene:
    """A scene with a lamp above the origin, rendered with 2 samples, depth 4."""
    settings_ = rtpy.RenderSettings(spp=2, max_depth=4)
    lamp = PointLight(V(0, 1, 0), BRIGHTEST)
    return Scene(
        objects, [lamp, *point_lights], camera=camera or eye(), settings=settings_, **scene
    )


def glossy_floors():
    for make in (Phong, BlinnPhong):
        yield make.__name__, make(Color(1, 1, 1), 0.5, 0.5, 1e6)
    for distribution in ("ggx", "beckmann"):
        yield (
            f"cook_torrance {distribution}",
            CookTorrance(Color(1, 1, 1), 0, 1, 1e-4, distribution),
        )
    yield "ward", Ward(Color(1, 1, 1), 0, 1, 1e-4, 1e-4)


def glass_balls():
    for ior in (1e-2, 100.0):
        yield f"dielectric {ior}", Dielectric(ior)
        for distribution in ("ggx", "beckmann"):
            yield f"rough_dielectric {ior} {distribution}", RoughDielectric(ior, 1e-4, distribution)
        yield f"cook_torrance ior {ior}", CookTorrance(Color(1, 1, 1), 0.5, 0.5, 1e-4, ior=ior)


def issue_examples():
    """(name, scene) of each of the issue's examples at the ends of the ranges."""
    far = V(0, 0, -1e6)
    yield "sphere light r=1e-6, emit 1e9, 1e6 away", lit([Sphere(far, 1e-6, LAMP), floor(GREY)])
    tiny_quad = Quad(V(0, 0, -1), V(1e-6, 0, 0), V(0, 1e-6, 0), LAMP)
    yield "quad light of 1e-6 edges, emit 1e9", lit([tiny_quad, floor(GREY)])
    yield (
        "point light 1e-6 above a floor",
        lit([floor(GREY)], [PointLight(V(0, -1 + 1e-6, -1), BRIGHTEST)], eye(look_at=V(0, -1, -1))),
    )
    bubble = Sphere(V(0, 0, 0), 1e-6, GREY)
    yield (
        "point light at the eye in a 1e-6 sphere",
        lit([bubble], [PointLight(V(0, 0, 0), BRIGHTEST)]),
    )
    yield (
        "point light near the eye in a 1e-6 sphere",
        lit([bubble], [PointLight(V(5e-7, 0, 0), BRIGHTEST)]),
    )
    for name, material in glossy_floors():
        grazing = PointLight(V(0, -1 + 1e-6, -1e6), BRIGHTEST)
        yield (
            f"{name} at grazing angles",
            lit(
                [floor(material), Sphere(V(0, -1 + 2e-6, -5e5), 1e-6, LAMP)],
                [grazing],
                eye(look_from=V(0, -1 + 1e-6, 0), look_at=V(0, -1, -1e6)),
            ),
        )
    for name, material in glass_balls():
        ball = Sphere(V(0, 0, -2), 1.0, material)
        yield f"{name} seen from outside", lit([ball, floor(GREY), Sphere(V(0, 3, -2), 0.5, LAMP)])
        yield f"{name} seen from inside", lit([Sphere(V(0, 0, 0), 1.0, material), floor(GREY)])
    corner = V(1e6, 1e6, 1e6)
    specks = [
        Sphere(V(1e6, 1e6, 1e6 - 1e-5), 1e-6, GREY),
        Sphere(V(1e6, 1e6 - 1e-5, 1e6), 1e-6, LAMP),
    ]
    yield (
        "radius 1e-6 at coordinates 1e6",
        lit(specks, [PointLight(corner, BRIGHTEST)], eye(corner, V(1e6, 1e6, 1e6 - 1e-5))),
    )
    board = Lambertian(CheckerTexture(1e-6, Color(1, 0, 0), Color(0, 1, 0)))
    far_floor = Quad(V(-1e6, 1e6 - 2, -1e6), V(1e6, 0, 0), V(0, 0, 1e6), board)
    yield (
        "checker scale 1e-6 at coordinates 1e6",
        lit([far_floor], camera=eye(V(-5e5, 1e6 - 1, -5e5), V(-5e5 + 1, 1e6 - 2, -5e5)), sky=True),
    )
    yield "look_at 1e-6 from the eye", lit([floor(GREY)], camera=eye(look_at=V(0, 0, -1e-6)))
    for focus in (1e-6, 1e6):
        lens = eye(focus_distance=focus, defocus_angle=179.0)
        yield f"focus distance {focus}, defocus 179", lit([floor(GREY)], camera=lens)
    for vfov in (1e-3, 179.0):
        yield f"vfov {vfov}", lit([Sphere(far, 1e-6, GREY), floor(GREY)], camera=eye(vfov=vfov))
    giants = [Sphere(V(0, 0, -1e6), 1e6 - 1.0, GREY), Sphere(V(0, 0, 1e6), 1e6 - 1.0, LAMP)]
    yield "spheres of radius 1e6 at 1e6", lit(giants)
    yield "metal of fuzz 1e6", lit([floor(Metal(Color(1, 1, 1), 1e6))], sky=True)


EXAMPLES = dict(issue_examples())


@pytest.mark.parametrize("name", EXAMPLES)
def test_issue_examples_at_the_ends_of_the_ranges_render_finite_pixels(name):
    assert_renders_finite(EXAMPLES[name], name)
