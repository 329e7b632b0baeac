"""Week 03 probes: what the graders of test_week03.py (and the hidden checks) ask the
student's code, run in the student's process (see rtpy/grading/probes.py). Each takes
plain data, calls the week's task methods and returns plain data; the verdicts are
the graders'."""

import numpy as np

import rtpy.vec3 as vec3
from rtpy import Camera, Color, HitInfo, Interval, Ray, Scene, Vec3
from rtpy.grading.probes import color, floats, make_material, probe, scene_builder, vec
from rtpy.grading.protocol import Array, Bool, Float, List, Record, Vec
from rtpy.integrators import center
from rtpy.sampling import make_generator, use_generator


@probe(returns=List(Vec))
def vec3_cross(cases: list):
    """vec3.cross(a, b) for each case [a, b] (looked up in the module when called)."""
    return [floats(vec3.cross(vec(a), vec(b))) for a, b in cases]


@probe(returns=List(Vec))
def vec3_unit_vector(cases: list):
    """vec3.unit_vector(v) for each case v."""
    return [floats(vec3.unit_vector(vec(v))) for v in cases]


def make_interval(spec) -> Interval:
    """Interval.empty() or Interval.universe() for "empty" or "universe", else
    Interval(min, max) for [min, max]."""
    if spec == "empty":
        return Interval.empty()
    if spec == "universe":
        return Interval.universe()
    lo, hi = spec
    return Interval(float(lo), float(hi))


@probe(returns=List(Record(contains=Bool, surrounds=Bool, clamp=Float)))
def interval_queries(cases: list):
    """contains(x), surrounds(x) and clamp(x) of the interval of each case
    {"interval": [min, max] or "empty" or "universe", "x": x}."""
    out = []
    for c in cases:
        interval, x = make_interval(c["interval"]), float(c["x"])
        out.append(
            {
                "contains": bool(interval.contains(x)),
                "surrounds": bool(interval.surrounds(x)),
                "clamp": float(interval.clamp(x)),
            }
        )
    return out


def make_camera(spec: dict) -> Camera:
    """Camera(look_from, look_at, vup, vfov, aspect_ratio, width, focus_distance) of a spec
    with those keys (points as three numbers)."""
    return Camera(
        vec(spec["look_from"]),
        vec(spec["look_at"]),
        vec(spec["vup"]),
        vfov=float(spec["vfov"]),
        aspect_ratio=float(spec["aspect_ratio"]),
        width=int(spec["width"]),
        focus_distance=float(spec["focus_distance"]),
    )


@probe(returns=List(Array((2, 3))))
def camera_center_rays(cases: list):
    """[origin, direction] of Camera(**camera).get_center_ray(i, j) for each case
    {"camera": spec (make_camera), "pixel": [i, j]}."""
    out = []
    for c in cases:
        i, j = c["pixel"]
        ray = make_camera(c["camera"]).get_center_ray(int(i), int(j))
        out.append(np.array([floats(ray.origin), floats(ray.direction)]))
    return out


@probe(returns=Array((None, 2, 3)))
def camera_jittered_rays(camera: dict, pixel: list, n: int, seed: int, stream: int):
    """(n, 2, 3): origin and direction of n calls of Camera(**camera).get_ray(i, j), rtpy's
    generator seeded with (seed, stream)."""
    cam, (i, j) = make_camera(camera), pixel
    rays = np.empty((int(n), 2, 3))
    with use_generator(make_generator(int(seed), int(stream))):
        for k in range(int(n)):
            ray = cam.get_ray(int(i), int(j))
            rays[k] = floats(ray.origin), floats(ray.direction)
    return rays


class FakeScene:
    """A scene whose every ray hits `hit` (or nothing), for flat_color."""

    def __init__(self, hit, background: Color) -> None:
        self.hit, self.background = hit, background

    def find_intersection(self, ray, interval):
        return self.hit

    def background_radiance(self, direction):
        return self.background


@probe(returns=List(Vec))
def flat_color_of_hits(cases: list, background: list):
    """center.flat_color(ray, scene) of a ray along -z in a FakeScene whose every ray
    hits the case's surface, or nothing for None: a case is None or {"material":
    material spec (make_material), "front_face": bool}, the hit at (0, 0, -1) with
    normal (0, 0, 1) and t = 1."""
    ray = Ray(Vec3(0, 0, 0), Vec3(0, 0, -1))
    out = []
    for c in cases:
        hit = None
        if c is not None:
            material = make_material(c["material"])
            hit = HitInfo(Vec3(0, 0, -1), Vec3(0, 0, 1), 1.0, bool(c["front_face"]), material)
        out.append(floats(center.flat_color(ray, FakeScene(hit, color(background)))))
    return out


# --- the scene the graders render ------------------------------------------------------
@scene_builder
def week03_sky():
    """The graded render: the sky alone (nothing can be hit before week 4)."""
    camera = Camera(Vec3(0, 0, 0), Vec3(0, 0.3, -1), vfov=90, aspect_ratio="16:9", width=32)
    return Scene([], sky=True, camera=camera)
