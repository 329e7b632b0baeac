"""Random valid scene files (as parsed TOML dicts) for the fuzz tests.

A scene made here follows the scene-format contract: every value is inside its
documented range, so the loader must accept it and both backends must render it.
The values lean on the edges of those ranges (tiny and huge radii, sliver
triangles, exponents of 10^4, roughness 10^-3, ior close to 1, cameras inside
objects, point lights on surfaces), where a naive formula gives NaN or Inf.

Hypothesis draws a seed and `random_scene` builds the scene from it with
random.Random: nested hypothesis strategies cost over 100 ms per scene here, more
than rendering it. A failing example is reported with its seed and the scene's text.

FUZZ_EXAMPLES scales the number of examples of the fuzz tests (default 1; CI uses
the default, derandomized, so a run is reproducible).
"""

from __future__ import annotations

import math
import os
import random

from hypothesis import HealthCheck, Phase, settings
from hypothesis import strategies as st

from rtpy.materials import MATERIALS
from rtpy.render_settings import INTEGRATOR_NAMES

FUZZ_SCALE = float(os.environ.get("FUZZ_EXAMPLES", "1"))

seeds = st.integers(0, 2**64 - 1)


def examples(n: int) -> int:
    """n examples, times FUZZ_EXAMPLES."""
    return max(1, int(n * FUZZ_SCALE))


def fuzz_settings(n: int) -> settings:
    """The hypothesis settings of a fuzz test: examples(n) examples, derandomized, with
    no deadline and no complaint about slow examples (each renders or runs a command);
    a failure is shrunk but not explained."""
    return settings(
        max_examples=examples(n),
        derandomize=True,
        deadline=None,
        suppress_health_check=[HealthCheck.too_slow],
        phases=[Phase.explicit, Phase.reuse, Phase.generate, Phase.shrink],
    )


def cross(a, b) -> list[float]:
    return [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]


def norm(v) -> float:
    """|v| as rtpy's Vec3.length computes it (underflows to 0 where hypot would not)."""
    return math.sqrt(sum(x * x for x in v))


def add(a, b, s: float = 1.0) -> list[float]:
    return [x + s * y for x, y in zip(a, b, strict=True)]


class SceneMaker:
    """Draws the parts of a valid scene from a random.Random."""

    def __init__(self, rng: random.Random, image_path: str | None = None) -> None:
        self.rng = rng
        self.image_path = image_path

    def edge(self, value: float, *edges: float) -> float:
        """value, or one of the edge values a third of the time."""
        return self.rng.choice(edges) if edges and self.rng.random() < 1 / 3 else value

    def uniform(self, lo: float, hi: float, *edges: float) -> float:
        return self.edge(self.rng.uniform(lo, hi), *edges)

    def log_uniform(self, lo: float, hi: float, *edges: float) -> float:
        """lo to hi (> 0), uniform in the exponent."""
        e = self.rng.uniform(math.log10(lo), math.log10(hi))
        return self.edge(10.0**e, *edges)

    def triple(self, lo: float, hi: float, *edges: float) -> list[float]:
        return [self.uniform(lo, hi, *edges) for _ in range(3)]

    def colour(self) -> list[float]:
        return self.triple(0.0, 1.0, 0.0, 1.0)

    def direction(self) -> list[float]:
        v = self.triple(-1.0, 1.0, 0.0, 1.0)
        return v if norm(v) > 1e-3 else [0.0, 0.0, -1.0]

    def texture(self) -> dict:
        kinds = ["solid", "checker"] + (["image"] if self.image_path else [])
        kind = self.rng.choice(kinds)
        if kind == "solid":
            return {"type": "solid", "color": self.colour()}
        if kind == "checker":
            scale = self.log_uniform(1e-3, 1e3)
            return {"type": "checker", "scale": scale, "even": self.colour(), "odd": self.colour()}
        return {"type": "image", "path": self.image_path}

    def material(self, textures: list[str]) -> dict:
        """A material of any registered kind, each key given or left to its default."""
        r = self
        kind = r.rng.choice(sorted(MATERIALS))

        def albedo():
            return r.rng.choice(textures) if textures and r.rng.random() < 0.3 else r.colour()

        keys = {"albedo": albedo}
        if kind == "diffuse_light":
            keys = {
                "emit": lambda: r.triple(0.0, 20.0, 0.0, 1e3),
                "two_sided": lambda: r.rng.random() < 0.5,
            }
        elif kind == "dielectric":
            keys = {"ior": lambda: r.log_uniform(0.2, 5.0, 1.0, 1.5), "albedo": r.colour}
        elif kind == "rough_dielectric":
            keys = {
                "ior": lambda: r.log_uniform(0.2, 5.0, 1.0, 1.5),
                "roughness": lambda: r.log_uniform(1e-3, 1.0, 1e-3, 1.0),
                "distribution": lambda: r.rng.choice(["ggx", "beckmann"]),
                "tint": r.colour,
            }
        elif kind == "metal":
            keys["fuzz"] = lambda: r.uniform(0.0, 2.0, 0.0)
        elif kind == "oren_nayar":
            keys["sigma"] = lambda: r.uniform(0.0, 89.9, 0.0, 89.9)
        elif kind in ("phong", "blinn_phong"):
            keys["exponent"] = lambda: r.log_uniform(1e-2, 1e4, 0.0, 1.0, 1e4)
        elif kind == "cook_torrance":
            keys["roughness"] = lambda: r.log_uniform(1e-3, 1.0, 1e-3, 1.0)
            keys["distribution"] = lambda: r.rng.choice(["ggx", "beckmann"])
            if r.rng.random() < 0.5:
                keys["ior"] = lambda: r.log_uniform(1.0001, 10.0, 1.0001, 1.5)
            else:
                keys["f0"] = r.colour
        elif kind == "ward":
            keys["alpha_x"] = lambda: r.log_uniform(1e-3, 1.0, 1e-3, 1.0)
            keys["alpha_y"] = lambda: r.log_uniform(1e-3, 1.0, 1e-3, 1.0)
        if kind in ("phong", "blinn_phong", "cook_torrance", "ward"):
            keys["kd"] = keys["ks"] = lambda: r.uniform(0.0, 1.0, 0.0, 1.0)
        table: dict = {"type": kind}
        for key, value in keys.items():
            if key == "emit" or r.rng.random() < 0.7:
                table[key] = value()
        return table

    def shape(self, material: str) -> dict:
        r = self
        kind = r.rng.choice(["sphere", "quad", "triangle"])
        q = r.triple(-4.0, 4.0, 0.0)
        if kind == "sphere":
            radius = r.log_uniform(1e-3, 1e3, 1e-3, 1e3, 1e5)
            return {"type": "sphere", "center": q, "radius": radius, "material": material}
        e1, e2 = r.triple(-3.0, 3.0, 0.0), r.triple(-3.0, 3.0, 0.0)
        if r.rng.random() < 0.4:  # on a grid, as in a Cornell box: shared planes and edges
            q = [float(r.rng.randint(-2, 2)) for _ in range(3)]
            i, j = r.rng.sample(range(3), 2)
            e1, e2 = [0.0, 0.0, 0.0], [0.0, 0.0, 0.0]
            e1[i], e2[j] = r.rng.choice([-2.0, -1.0, 1.0, 2.0]), r.rng.choice([-2.0, 1.0, 2.0])
        elif r.rng.random() < 0.3:  # a sliver: e2 almost along e1
            e2 = add([x * r.uniform(-2.0, 2.0) for x in e1], e2, r.log_uniform(1e-12, 1e-2))
        if kind == "quad":
            if not norm(cross(e1, e2)) > 0.0:
                e1, e2 = [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]
            return {"type": "quad", "q": q, "u": e1, "v": e2, "material": material}
        b, c = add(q, e1), add(q, e2)
        if not norm(cross(add(b, q, -1.0), add(c, q, -1.0))) > 0.0:  # rounded to a line
            b, c = add(q, [1.0, 0.0, 0.0]), add(q, [0.0, 1.0, 0.0])
        return {"type": "triangle", "a": q, "b": b, "c": c, "material": material}

    def camera(self, target: list[float] | None = None) -> dict:
        """A camera anywhere, looking at `target` (when given and not too close) or
        in a random direction."""
        r = self
        look_from = r.triple(-4.0, 4.0, 0.0)
        view = r.direction()
        if target is not None and norm(add(target, look_from, -1.0)) > 1e-3:
            view = add(target, look_from, -1.0)
        vup = r.direction()
        if not norm(cross(vup, view)) > 1e-3 * norm(vup) * norm(view):
            axis = [0.0, 0.0, 0.0]
            axis[min(range(3), key=lambda i: abs(view[i]))] = 1.0  # the axis most across view
            vup = cross(view, axis)
        camera = {
            "look_from": look_from,
            "look_at": add(look_from, view),
            "vup": vup,
            "vfov": r.uniform(1.0, 170.0, 1.0, 90.0, 170.0),
            "aspect_ratio": r.rng.choice([1.0, 4 / 3, 16 / 9, "8:6", 2]),
            "width": r.rng.randint(4, 8),
        }
        if r.rng.random() < 0.5:  # thin lens
            camera["defocus_angle"] = r.uniform(0.0, 60.0, 10.0)
            camera["focus_distance"] = r.log_uniform(1e-2, 1e2)
        return camera

    def render(self) -> dict:
        r = self.rng
        table = {
            "integrator": r.choice(INTEGRATOR_NAMES),
            "spp": r.randint(1, 2),
            "max_depth": r.randint(1, 4),
            "nee": r.random() < 0.5,
            "russian_roulette": r.randint(0, 3),
            "seed": r.randint(0, 2**32),
            "gamma": r.choice([1.0, 2.2]),
            "shadows": r.random() < 0.5,
        }
        if r.random() < 0.5:  # the lecture's fixed p_RR, in (0, 1]
            table["roulette"] = "fixed"
            table["roulette_probability"] = 1.0 - r.random()
        if r.random() < 0.5:
            table["sky"] = True
        else:
            table["background"] = self.triple(0.0, 2.0)
        return table

    def scene(self) -> dict:
        r = self.rng
        textures = {f"t{i}": self.texture() for i in range(r.randint(0, 2))}
        materials = {f"m{i}": self.material(sorted(textures)) for i in range(r.randint(1, 4))}
        names = sorted(materials)
        objects = [self.shape(r.choice(names)) for _ in range(r.randint(1, 5))]
        target = r.choice(objects)
        target = target.get("center") or target.get("q") or target.get("a")
        data = {
            "camera": self.camera(target if r.random() < 0.8 else None),
            "render": self.render(),
            "materials": materials,
            "objects": objects,
        }
        if textures:
            data["textures"] = textures
        lights = [
            {"type": "point", "position": self.triple(-4.0, 4.0, 0.0),
             "intensity": self.triple(0.0, 20.0, 0.0, 1e3)}
            for _ in range(r.randint(0, 2))
        ]  # fmt: skip
        if lights:
            data["lights"] = lights
        return data


def random_scene(seed: int, image_path: str | None = None) -> dict:
    """A parsed scene file (dict) that the contract says is valid."""
    return SceneMaker(random.Random(seed), image_path).scene()
