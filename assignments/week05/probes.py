"""Week 05 probes: what the graders of test_week05.py (and the hidden checks) ask the
student's code, run in the student's process (see rtpy/grading/probes.py). Each takes
plain data, calls the week's task methods and returns plain data; the verdicts are
the graders'."""

from rtpy import Color, HitInfo, Interval, Lambertian, PointLight, Quad, Ray, Scene, Sphere, Vec3
from rtpy.grading.probes import (
    SCENES,
    color,
    floats,
    given_code_unused,
    probe,
    scene_builder,
    vec,
)
from rtpy.grading.protocol import Bool, Float, List, Maybe, Record, Vec
from rtpy.integrators import direct_lighting
from rtpy.light import LightSample
from rtpy.materials import DiffuseLight
from rtpy.sampling import make_generator, use_generator
from rtpy.vec3 import BLACK, dot

LIGHT_SAMPLE = Record(direction=Vec, distance=Float, radiance=Vec, pdf=Float, is_delta=Bool)


@probe(returns=List(Maybe(LIGHT_SAMPLE)))
def point_light_sample(cases: list):
    """PointLight(position, intensity).sample(point) for each case."""
    out = []
    for c in cases:
        s = PointLight(vec(c["position"]), color(c["intensity"])).sample(vec(c["point"]))
        if s is None:
            out.append(None)
            continue
        out.append(
            {
                "direction": floats(s.direction),
                "distance": float(s.distance),
                "radiance": floats(s.radiance),
                "pdf": float(s.pdf),
                "is_delta": bool(s.is_delta),
            }
        )
    return out


@probe(returns=List(Bool))
def find_occlusion(ray: list, cases: list):
    """Scene(spheres).find_occlusion(ray, Interval(lo, hi)) for each case, the spheres
    given as [center, radius], with the BVH's code watched (it answers the task)."""
    origin, direction = ray
    out = []
    for c in cases:
        scene = Scene([Sphere(vec(center), float(r), Lambertian()) for center, r in c["spheres"]])
        lo, hi = c["interval"]
        with given_code_unused(("rtpy.bvh",), "Scene.find_occlusion (rtpy/scene.py)"):
            got = scene.find_occlusion(Ray(vec(origin), vec(direction)), Interval(lo, hi))
        out.append(got if isinstance(got, bool) else bool(got))
    return out


class FlatBRDF:
    """A stand-in material with f_r = f above the surface, so that the estimate's
    grader does not depend on Lambertian."""

    is_specular = False

    def __init__(self, f: Color) -> None:
        self.f = f

    def BRDF(self, ray_view, ray_light, hit):
        return self.f if dot(hit.normal, ray_light.direction) > 0.0 else BLACK


@probe(returns=List(Vec))
def light_sample_estimate(cases: list, f: list):
    """light_sample_estimate(Scene(objects), ray_in, hit, sample, light_shape) for each
    case: a hit on a surface of FlatBRDF(f) with normal (0, 1, 0) at `point`, seen from
    `eye`, a LightSample toward `light`, objects: spheres [center, radius, emits?],
    light_shape: the index of the object that is the light's own shape, or None."""
    material = FlatBRDF(color(f))
    out = []
    for c in cases:
        p, light = vec(c["point"]), vec(c["light"])
        to_light = light - p
        dist = to_light.length()
        sample = LightSample(
            to_light / dist, dist, color(c["radiance"]), float(c["pdf"]), False, light
        )
        hit = HitInfo(p, Vec3(0, 1, 0), 1.0, True, material)
        eye = vec(c["eye"])
        ray_in = Ray(eye, (p - eye) / (p - eye).length())
        objects = [
            Sphere(vec(center), float(r), DiffuseLight(Color(1, 1, 1)) if emits else Lambertian())
            for center, r, emits in c["objects"]
        ]
        shape = None if c["light_shape"] is None else objects[c["light_shape"]]
        got = direct_lighting.light_sample_estimate(Scene(objects), ray_in, hit, sample, shape)
        out.append(floats(got))
    return out


@probe(returns=List(List(Vec)))
def sample_one_light(scene: str, cases: list, seed: int):
    """sample_one_light(built, incoming, hit, built.lights) at floor points, for each case
    {"params": the scene's parameters, "points": [...]}: built = SCENES[scene](**params),
    a hit on its first object (a floor facing +y) at each point, the incoming ray from
    above; one generator, seeded with seed, for all of them, in order."""
    out = []
    with use_generator(make_generator(int(seed), 5)):
        for case in cases:
            built = SCENES[scene](**case["params"])
            floor = built.objects[0]
            values = []
            for point in case["points"]:
                p = vec(point)
                hit = floor.hit_info(Ray(p + Vec3(0, 1e-3, 0), Vec3(0, -1, 0)), 1e-3)
                incoming = Ray(p + Vec3(0, 1, 0), Vec3(0, -1, 0))
                lit = direct_lighting.sample_one_light(built, incoming, hit, built.lights)
                values.append(floats(lit))
            out.append(values)
    return out


# --- the scenes the graders render or look into ------------------------------------------
def big_floor(albedo=(0.5, 0.5, 0.5), height: float = 0.0):
    return Quad(Vec3(-50, height, -50), Vec3(0, 0, 100), Vec3(100, 0, 0), Lambertian(color(albedo)))


@scene_builder
def lit_plane(albedo: list, light: list, intensity: list, occluder: list | None = None):
    """A large floor at y = 0 under a point light, and a sphere [center, radius] above."""
    objects = [big_floor(albedo)]
    if occluder is not None:
        objects.append(Sphere(vec(occluder[0]), float(occluder[1]), Lambertian()))
    return Scene(objects, [PointLight(vec(light), color(intensity))])


@scene_builder
def area_light():
    """The graded render: two spheres on a floor under a sphere light and a point light."""
    from rtpy import Camera

    red, white = Lambertian(Color(0.7, 0.2, 0.2)), Lambertian(Color(0.7, 0.7, 0.7))
    objects = [
        Quad(Vec3(-3, 0, -5), Vec3(6, 0, 0), Vec3(0, 0, 5), white),
        Sphere(Vec3(-0.6, 0.5, -2.5), 0.5, red),
        Sphere(Vec3(0.8, 0.4, -2.0), 0.4, white),
        Sphere(Vec3(0.0, 2.2, -2.2), 0.4, DiffuseLight(Color(6.0, 6.0, 5.0))),
    ]
    camera = Camera(Vec3(0, 1.0, 0.5), Vec3(0, 0.6, -2.5), vfov=60, aspect_ratio="16:9", width=32)
    return Scene(objects, [PointLight(Vec3(1.5, 1.5, -1.0), Color(1.5, 1.5, 1.5))], camera=camera)


@scene_builder
def glowing_ball(emit: list, background: list):
    """One light sphere at (0, 0, -3), radius 1, before a background."""
    return Scene(
        [Sphere(Vec3(0, 0, -3), 1.0, DiffuseLight(color(emit)))], background=color(background)
    )


@scene_builder
def floor_and_ceiling(albedo: list, light: list, intensity: list, top: float):
    """A floor at y = 0 and a ceiling at y = top above a point light between them."""
    ceiling = Quad(Vec3(-50, top, -50), Vec3(100, 0, 0), Vec3(0, 0, 100), Lambertian())
    return Scene([big_floor(albedo), ceiling], [PointLight(vec(light), color(intensity))])


@scene_builder
def lamp_under_wall(albedo: list, center: list, radius: float):
    """A floor at y = 0, a sphere light (emission 4) and a sphere above and beyond it."""
    c = vec(center)
    lamp = Sphere(c, float(radius), DiffuseLight(Color(4, 4, 4)))
    wall = Sphere(c + Vec3(0, 3.0, 0), 2.0, Lambertian())
    return Scene([big_floor(albedo), lamp, wall])


@scene_builder
def lit_sphere(albedo: list, center: list, radius: float, light: list, intensity: list):
    """A sphere under a point light."""
    sphere = Sphere(vec(center), float(radius), Lambertian(color(albedo)))
    return Scene([sphere], [PointLight(vec(light), color(intensity))])


@scene_builder
def lit_floor(albedo: list, corner: list, light: list, intensity: list):
    """A large horizontal floor from corner under a point light."""
    plane = Quad(vec(corner), Vec3(0, 0, 100), Vec3(100, 0, 0), Lambertian(color(albedo)))
    return Scene([plane], [PointLight(vec(light), color(intensity))])
