"""Scenes whose every number lies anywhere in its allowed range, however extreme,
render finite, non-negative pixels on both backends with every integrator.

The ranges are the scene-format contract:
- coordinates of points: each component in [-1e6, 1e6], subnormals and 0 included;
- lengths (radius, |quad u|, |quad v|, focus distance, |look_at - look_from|,
  checker scale): [1e-6, 1e6]; |u x v| of a quad and twice a triangle's area >= 1e-12;
- |vup| >= 1e-6 and the sine of its angle to the view direction >= 1e-6; vfov in
  [1e-3, 179] degrees, defocus_angle in [0, 179];
- reflectances (albedo, kd, ks, f0) in [0, 1]; radiances (emit, background, point
  intensity) in [0, 1e9]; exponent in [0, 1e6]; roughness and alpha in [1e-4, 1];
  ior in [1e-2, 100]; fuzz in [0, 1e6].

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

import pytest
from hypothesis import HealthCheck, given, settings
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
    Sphere,
    Triangle,
    Vec3,
)
from rtpy.io.scene_file import load_scene_text
from rtpy.materials import MATERIALS, BlinnPhong, Phong, RoughDielectric, Ward
from rtpy.render_settings import INTEGRATOR_NAMES
from tests.io.scene_text import to_toml
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
# Distances from an anchor to a light or an object's corner: every magnitude.
SPAN = extreme_floats(SMALLEST, 2.0 * MAX_COORD)


def triple(values: st.SearchStrategy[float]) -> st.SearchStrategy[list[float]]:
    return st.lists(values, min_size=3, max_size=3)


@st.composite
def directions(draw) -> list[float]:
    """A unit vector, its components of any magnitude (axis-aligned to within 1e-300)."""
    v = draw(triple(extreme_floats(SMALLEST, 1.0, signed=True, zero=True)))
    length = norm(v)
    return [x / length for x in v] if length > 1e-3 else [0.0, 0.0, -1.0]


def offset(p: list[float], v: list[float]) -> list[float]:
    """p + v, each component of v turned toward 0 where p + v would leave the range."""
    out = []
    for a, b in zip(p, v, strict=True):
        out.append(a + b if abs(a + b) <= MAX_COORD else a - math.copysign(abs(b), a))
    return out


def scaled(v: list[float], s: float) -> list[float]:
    return [x * s for x in v]


@st.composite
def cameras(draw) -> dict:
    look_from = draw(triple(COORD))
    view, distance = draw(directions()), draw(LENGTH)
    look_at = offset(look_from, scaled(view, distance))
    while not norm(add(look_at, look_from, -1.0)) >= 1e-6:  # rounded below the least
        distance *= 1.5
        look_at = offset(look_from, scaled(view, distance))
    view = add(look_at, look_from, -1.0)
    vup = scaled(draw(directions()), draw(LENGTH))
    if not norm(cross(vup, view)) >= 2e-6 * norm(vup) * norm(view):
        axis = [0.0, 0.0, 0.0]
        axis[min(range(3), key=lambda i: abs(view[i]))] = 1.0  # the axis most across view
        vup = cross(view, axis)
        vup = scaled(vup, 1.0 / norm(vup))
    camera = {"look_from": look_from, "look_at": look_at, "vup": vup, "vfov": draw(VFOV)}
    camera |= {"aspect_ratio": 1.0, "width": 4}
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


@st.composite
def shapes(draw, anchor: list[float], material: str) -> dict:
    """A sphere, quad or triangle at (or at any distance from) the anchor."""
    at = offset(anchor, scaled(draw(directions()), draw(SPAN))) if draw(st.booleans()) else anchor
    kind = draw(st.sampled_from(["sphere", "quad", "triangle"]))
    if kind != "sphere":
        edges = [scaled(draw(directions()), draw(LENGTH)) for _ in range(2)]
        q, (u, v) = fit_edges(at, edges)
        if kind == "quad" and norm(cross(u, v)) >= 2e-12 and min(norm(u), norm(v)) >= 1e-6:
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
    textures = {}
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
    if textures:
        data["textures"] = textures
    if lights:
        data["lights"] = lights
    return data


def build(data: dict) -> Scene:
    """The scene of a parsed scene file, built through the Python API."""
    V = Vec3

    def value(x):
        if isinstance(x, str) and x in textures:
            return textures[x]
        return Color(*x) if isinstance(x, list) else x

    textures = {
        name: CheckerTexture(t["scale"], Color(*t["even"]), Color(*t["odd"]))
        for name, t in data.get("textures", {}).items()
    }
    mats = {
        name: MATERIALS[t["type"]](**{k: value(x) for k, x in t.items() if k != "type"})
        for name, t in data["materials"].items()
    }
    objects = []
    for o in data["objects"]:
        m = mats[o["material"]]
        if o["type"] == "sphere":
            objects.append(Sphere(V(*o["center"]), o["radius"], m))
        elif o["type"] == "quad":
            objects.append(Quad(V(*o["q"]), V(*o["u"]), V(*o["v"]), m))
        else:
            objects.append(Triangle(V(*o["a"]), V(*o["b"]), V(*o["c"]), m))
    lights = [PointLight(V(*p["position"]), Color(*p["intensity"])) for p in data.get("lights", [])]
    c = data["camera"]
    camera = Camera(
        V(*c["look_from"]), V(*c["look_at"]), V(*c["vup"]), c["vfov"], 1.0, c["width"],
        c.get("defocus_angle", 0.0), c.get("focus_distance", 10.0),
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


def check_scene_file(data: dict, tmp_path) -> None:
    text = to_toml(data)
    assert_renders_finite(load_scene_text(text, tmp_path / "extreme.toml"), text)


def check_python_api(data: dict) -> None:
    assert_renders_finite(build(data), repr(data))


@extreme(20)
@given(data=scene_files())
def test_extreme_scene_files_render_finite_pixels(tmp_path_factory, data):
    check_scene_file(data, tmp_path_factory.mktemp("extreme"))


@extreme(20)
@given(data=scene_files())
def test_extreme_scenes_built_in_python_render_finite_pixels(data):
    check_python_api(data)


@pytest.mark.slow
@extreme(150)
@given(data=scene_files())
def test_more_extreme_scene_files_render_finite_pixels(tmp_path_factory, data):
    check_scene_file(data, tmp_path_factory.mktemp("extreme"))


@pytest.mark.slow
@extreme(150)
@given(data=scene_files())
def test_more_extreme_scenes_built_in_python_render_finite_pixels(data):
    check_python_api(data)


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
