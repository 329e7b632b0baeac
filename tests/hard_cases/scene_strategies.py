"""Hypothesis strategies for random valid scene files (as parsed TOML dicts).

A scene drawn here follows the scene-format contract: every value is inside its
documented range, so the loader must accept it and both backends must render it.
The values lean on the edges of those ranges (tiny and huge radii, near-degenerate
triangles, exponents of 10^4, roughness 10^-3, ior close to 1, cameras inside
objects, point lights on surfaces), where a naive formula gives NaN or Inf.

FUZZ_EXAMPLES scales the number of examples of the fuzz tests (default 1; CI uses
the default, derandomized, so a run is reproducible).
"""

from __future__ import annotations

import math
import os

from hypothesis import strategies as st

from rtpy.materials import MATERIALS
from rtpy.render_settings import INTEGRATOR_NAMES

FUZZ_SCALE = float(os.environ.get("FUZZ_EXAMPLES", "1"))


def examples(n: int) -> int:
    """n examples, times FUZZ_EXAMPLES."""
    return max(1, int(n * FUZZ_SCALE))


def floats(lo: float, hi: float) -> st.SearchStrategy[float]:
    return st.floats(lo, hi, allow_nan=False, allow_infinity=False)


def log_uniform(lo: float, hi: float) -> st.SearchStrategy[float]:
    """Numbers from lo to hi (both > 0), uniform in their exponent."""
    return floats(math.log10(lo), math.log10(hi)).map(lambda e: 10.0**e)


def with_edges(strategy, *edges) -> st.SearchStrategy:
    """The strategy, or one of the given edge values a third of the time."""
    return st.one_of(strategy, strategy, st.sampled_from(edges))


UNIT = with_edges(floats(0.0, 1.0), 0.0, 1.0)
colour = st.lists(UNIT, min_size=3, max_size=3)
emission = st.lists(with_edges(floats(0.0, 20.0), 0.0, 1e3), min_size=3, max_size=3)
point = st.lists(with_edges(floats(-4.0, 4.0), 0.0), min_size=3, max_size=3)
direction = st.lists(with_edges(floats(-1.0, 1.0), 0.0, 1.0), min_size=3, max_size=3).map(
    lambda v: v if _norm(v) > 1e-3 else [0.0, 0.0, -1.0]
)


def _cross(a, b):
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def _norm(v) -> float:
    """|v| as rtpy's Vec3.length computes it (underflows to 0 where hypot would not)."""
    return math.sqrt(sum(x * x for x in v))


def _add(a, b, s=1.0):
    return [x + s * y for x, y in zip(a, b, strict=True)]


def _non_degenerate_quad(table: dict) -> dict:
    if not _norm(_cross(table["u"], table["v"])) > 0.0:
        table["u"], table["v"] = [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]
    return table


# --- textures and materials ------------------------------------------------------


def textures(image_path: str | None):
    kinds = ["solid", "checker"] + (["image"] if image_path else [])

    @st.composite
    def one(draw):
        kind = draw(st.sampled_from(kinds))
        if kind == "solid":
            return {"type": "solid", "color": draw(colour)}
        if kind == "checker":
            return {
                "type": "checker",
                "scale": draw(log_uniform(1e-3, 1e3)),
                "even": draw(colour),
                "odd": draw(colour),
            }
        return {"type": "image", "path": image_path}

    return st.dictionaries(st.sampled_from(["t0", "t1"]), one(), max_size=2)


GLOSSY_EXTRAS = {
    "phong": {"exponent": with_edges(log_uniform(1e-2, 1e4), 0.0, 1.0, 1e4)},
    "blinn_phong": {"exponent": with_edges(log_uniform(1e-2, 1e4), 0.0, 1.0, 1e4)},
    "cook_torrance": {
        "roughness": with_edges(log_uniform(1e-3, 1.0), 1e-3, 1.0),
        "distribution": st.sampled_from(["ggx", "beckmann"]),
        "ior": with_edges(log_uniform(1.0001, 10.0), 1.0001, 1.5),
        "f0": colour,
    },
    "ward": {
        "alpha_x": with_edges(log_uniform(1e-3, 1.0), 1e-3, 1.0),
        "alpha_y": with_edges(log_uniform(1e-3, 1.0), 1e-3, 1.0),
    },
}


def materials(texture_names: list[str]):
    """Materials of every registered kind, each key present or left to its default."""
    albedo = st.one_of(colour, st.sampled_from(texture_names)) if texture_names else colour

    @st.composite
    def one(draw):
        kind = draw(st.sampled_from(sorted(MATERIALS)))
        keys: dict = {}
        if kind == "diffuse_light":
            keys = {"emit": emission, "two_sided": st.booleans()}
        elif kind == "dielectric":
            keys = {"ior": with_edges(log_uniform(0.2, 5.0), 1.0, 1.5), "albedo": colour}
        elif kind == "metal":
            keys = {"albedo": albedo, "fuzz": with_edges(floats(0.0, 2.0), 0.0)}
        elif kind == "oren_nayar":
            keys = {"albedo": albedo, "sigma": with_edges(floats(0.0, 89.9), 0.0, 89.9)}
        else:  # lambertian, mirror and the glossy models
            keys = {"albedo": albedo}
        if kind in GLOSSY_EXTRAS:
            weight = with_edges(floats(0.0, 1.0), 0.0, 1.0)
            keys = {**keys, "kd": weight, "ks": weight, **GLOSSY_EXTRAS[kind]}
        table = {"type": kind}
        for key, strategy in keys.items():
            if kind == "diffuse_light" and key == "emit" or draw(st.booleans()):
                table[key] = draw(strategy)
        if kind == "cook_torrance" and "f0" in table and draw(st.booleans()):
            del table["f0"]
        return table

    return one()


# --- objects, lights, camera, settings ----------------------------------------------


def objects(material_names: list[str]):
    name = st.sampled_from(material_names)
    sphere = st.fixed_dictionaries(
        {
            "type": st.just("sphere"),
            "center": point,
            "radius": with_edges(log_uniform(1e-3, 1e3), 1e-3, 1e3, 1e5),
            "material": name,
        }
    )
    edge = st.lists(with_edges(floats(-3.0, 3.0), 0.0), min_size=3, max_size=3)
    quad = st.fixed_dictionaries(
        {"type": st.just("quad"), "q": point, "u": edge, "v": edge, "material": name}
    ).map(_non_degenerate_quad)

    @st.composite
    def triangle(draw):
        a, e1, e2 = draw(point), draw(edge), draw(edge)
        if draw(st.booleans()):  # a sliver: c almost on the line a-b
            thin = draw(log_uniform(1e-12, 1e-2))
            along = draw(floats(-2.0, 2.0))
            e2 = _add([x * along for x in e1], e2, thin)
        b, c = _add(a, e1), _add(a, e2)
        if not _norm(_cross(_add(b, a, -1.0), _add(c, a, -1.0))) > 0.0:
            b, c = _add(a, [1.0, 0.0, 0.0]), _add(a, [0.0, 1.0, 0.0])  # rounded to a line
        return {"type": "triangle", "a": a, "b": b, "c": c, "material": draw(name)}

    return st.lists(st.one_of(sphere, quad, triangle()), min_size=1, max_size=5)


point_lights = st.lists(
    st.fixed_dictionaries(
        {"type": st.just("point"), "position": point, "intensity": emission}
    ),
    max_size=2,
)


@st.composite
def cameras(draw):
    look_from = draw(point)
    look_at = _add(look_from, draw(direction))
    view = _add(look_at, look_from, -1.0)
    vup = draw(direction)
    if not _norm(_cross(vup, view)) > 1e-3 * _norm(vup) * _norm(view):
        axis = [0.0, 0.0, 0.0]
        axis[min(range(3), key=lambda i: abs(view[i]))] = 1.0  # the axis most across view
        vup = _cross(view, axis)
    camera = {
        "look_from": look_from,
        "look_at": look_at,
        "vup": vup,
        "vfov": draw(with_edges(floats(1.0, 170.0), 1.0, 90.0, 170.0)),
        "aspect_ratio": draw(st.sampled_from([1.0, 4 / 3, 16 / 9, "8:6", 2])),
        "width": draw(st.integers(4, 8)),
    }
    if draw(st.booleans()):  # thin lens
        camera["defocus_angle"] = draw(with_edges(floats(0.0, 60.0), 10.0))
        camera["focus_distance"] = draw(log_uniform(1e-2, 1e2))
    return camera


@st.composite
def render_tables(draw):
    table = {
        "integrator": draw(st.sampled_from(INTEGRATOR_NAMES)),
        "spp": draw(st.integers(1, 2)),
        "max_depth": draw(st.integers(1, 4)),
        "nee": draw(st.booleans()),
        "russian_roulette": draw(st.integers(0, 3)),
        "seed": draw(st.integers(0, 2**32)),
        "gamma": draw(st.sampled_from([1.0, 2.2])),
    }
    if draw(st.booleans()):
        table["sky"] = True
    else:
        table["background"] = draw(st.lists(floats(0.0, 2.0), min_size=3, max_size=3))
    return table


@st.composite
def scenes(draw, image_path: str | None = None):
    """A parsed scene file (dict) that the contract says is valid."""
    tex = draw(textures(image_path))
    mats = draw(
        st.dictionaries(
            st.sampled_from(["m0", "m1", "m2", "m3"]), materials(sorted(tex)), min_size=1
        )
    )
    data = {
        "camera": draw(cameras()),
        "render": draw(render_tables()),
        "materials": mats,
        "objects": draw(objects(sorted(mats))),
    }
    if tex:
        data["textures"] = tex
    lights = draw(point_lights)
    if lights:
        data["lights"] = lights
    return data
