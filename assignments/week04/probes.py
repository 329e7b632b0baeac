"""Week 04 probes: what the graders of test_week04.py (and the hidden checks) ask the
student's code, run in the student's process (see rtpy/grading/probes.py). Each takes
plain data, calls the week's task methods and returns plain data; the verdicts are
the graders'."""

from rtpy import Camera, Color, Interval, Lambertian, Quad, Ray, Scene, Sphere, Triangle, Vec3
from rtpy.grading.probes import floats, given_code_unused, probe, scene_builder, vec
from rtpy.grading.protocol import Bool, Float, Int, List, Maybe, Record, Vec

M = Lambertian()


def make_shape(spec: dict):
    """The shape of a spec: {"type": "Sphere", "center", "radius"}, {"type": "Quad",
    "corner", "u", "v"} or {"type": "Triangle", "a", "b", "c"} (points as three numbers),
    all of one Lambertian material."""
    kind = spec["type"]
    if kind == "Sphere":
        return Sphere(vec(spec["center"]), float(spec["radius"]), M)
    if kind == "Quad":
        return Quad(vec(spec["corner"]), vec(spec["u"]), vec(spec["v"]), M)
    if kind == "Triangle":
        return Triangle(vec(spec["a"]), vec(spec["b"]), vec(spec["c"]), M)
    raise ValueError(f"no shape {kind!r}")


def make_ray(case: dict) -> Ray:
    return Ray(vec(case["origin"]), vec(case["direction"]))


@probe(returns=List(Maybe(Float)))
def shape_hit_t(cases: list):
    """make_shape(shape).hit_t(Ray(origin, direction), t_min, t_max) for each case
    {"shape", "origin", "direction", "t_min", "t_max"}: None or a number."""
    out = []
    for c in cases:
        t = make_shape(c["shape"]).hit_t(make_ray(c), float(c["t_min"]), float(c["t_max"]))
        out.append(None if t is None else float(t))
    return out


@probe(returns=List(Record(point=Vec, normal=Vec, front_face=Bool)))
def sphere_hit_info(cases: list):
    """Sphere(center, radius).hit_info(Ray(origin, direction), t) for each case
    {"center", "radius", "origin", "direction", "t"}."""
    out = []
    for c in cases:
        sphere = Sphere(vec(c["center"]), float(c["radius"]), M)
        hit = sphere.hit_info(make_ray(c), float(c["t"]))
        out.append(
            {
                "point": floats(hit.point),
                "normal": floats(hit.normal),
                "front_face": bool(hit.front_face),
            }
        )
    return out


@probe(returns=List(Maybe(Record(t=Float, index=Int))))
def scene_closest_hit(cases: list):
    """Scene(spheres).find_intersection(Ray(origin, direction), Interval(lo, hi)) for
    each case {"spheres": [[center, radius], ...], "origin", "direction", "interval":
    [lo, hi]}: None, or the hit's t and the index in `spheres` of the object it names
    (hit.obj; -1 when it names none of them). The BVH's code is watched: it answers
    the task."""
    out = []
    for c in cases:
        spheres = [Sphere(vec(center), float(r), M) for center, r in c["spheres"]]
        lo, hi = c["interval"]
        scene, ray, interval = Scene(spheres), make_ray(c), Interval(float(lo), float(hi))
        with given_code_unused(("rtpy.bvh",), "Scene.find_intersection (rtpy/scene.py)"):
            hit = scene.find_intersection(ray, interval)
        if hit is None:
            out.append(None)
            continue
        index = next((k for k, s in enumerate(spheres) if s is hit.obj), -1)
        out.append({"t": float(hit.t), "index": index})
    return out


# --- the scene the graders render ------------------------------------------------------
@scene_builder
def week04_shapes():
    """The graded render: a floor quad, two spheres and a triangle."""
    red, green, blue = (
        Lambertian(Color(*c)) for c in ((0.8, 0.2, 0.2), (0.2, 0.8, 0.2), (0.2, 0.2, 0.8))
    )
    objects = [
        Quad(Vec3(-3, -0.5, -6), Vec3(6, 0, 0), Vec3(0, 0, 6), Lambertian(Color(0.5, 0.5, 0.5))),
        Sphere(Vec3(-0.9, 0.0, -2.0), 0.5, red),
        Triangle(Vec3(-0.3, -0.5, -2.5), Vec3(0.5, -0.5, -2.5), Vec3(0.1, 0.6, -2.3), green),
        Sphere(Vec3(0.9, 0.1, -2.4), 0.6, blue),
    ]
    camera = Camera(Vec3(0, 0.3, 0.5), Vec3(0, 0, -2), vfov=60, aspect_ratio="16:9", width=48)
    return Scene(objects, sky=True, camera=camera)
