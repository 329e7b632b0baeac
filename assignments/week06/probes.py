"""Week 06 probes: what the graders of test_week06.py (and the hidden checks) ask the
student's code, run in the student's process (see rtpy/grading/probes.py). Each takes
plain data, calls the week's task methods and returns plain data; the verdicts are
the graders'."""

from contextlib import nullcontext

import numpy as np

import rtpy.materials.dielectric as dielectric
import rtpy.vec3 as vec3
from rtpy import Camera, Color, HitInfo, Lambertian, PointLight, Quad, Ray, Scene, Sphere, Vec3
from rtpy.grading.probes import floats, make_material, probe, scene_builder, vec
from rtpy.grading.protocol import Array, Float, List, Vec
from rtpy.materials import Dielectric, Mirror
from rtpy.sampling import make_generator, use_generator

# One row per call of scattering(): status (0: None, 1: a sample), the scattered
# direction (3), the attenuation (3) and is_specular (0 or 1); zeros after a None.
SCATTERS = Array((None, 8))


@probe(returns=List(Vec))
def week06_reflect(cases: list):
    """reflect(v, n) for each case [v, n]."""
    return [floats(vec3.reflect(vec(d), vec(n))) for d, n in cases]


@probe(returns=List(Vec))
def week06_refract(cases: list):
    """refract(uv, n, etai_over_etat) for each case [uv, n, eta]."""
    return [floats(vec3.refract(vec(d), vec(n), float(eta))) for d, n, eta in cases]


@probe(returns=List(Float))
def week06_schlick(cases: list):
    """dielectric.schlick(cosine, ior_ratio) for each case [cosine, ratio]."""
    return [float(dielectric.schlick(float(c), float(r))) for c, r in cases]


def scatter_rows(material, ray: Ray, hit: HitInfo, count: int) -> np.ndarray:
    rows = np.zeros((count, 8))
    for k in range(count):
        s = material.scattering(ray, hit)
        if s is not None:
            rows[k] = [1.0, *floats(s.scattered_ray.direction), *floats(s.attenuation),
                       float(bool(s.is_specular))]  # fmt: skip
    return rows


@probe(returns=List(SCATTERS))
def week06_scatter(cases: list, generator: list | None = None):
    """`count` calls of material.scattering(ray, hit) for each case {"material": spec
    (rtpy.grading.probes.make_material), "origin", "direction": the incoming ray,
    "normal", "front_face", "count"}, the hit at the origin of the world; all of them,
    in order, with rtpy's generator make_generator(*generator) (when given)."""
    out = []
    with use_generator(make_generator(*generator)) if generator else nullcontext():
        for c in cases:
            material = make_material(c["material"])
            front_face = bool(c["front_face"])
            hit = HitInfo(Vec3(0, 0, 0), vec(c["normal"]), 1.0, front_face, material)
            ray = Ray(vec(c["origin"]), vec(c["direction"]))
            out.append(scatter_rows(material, ray, hit, int(c["count"])))
    return out


# --- the scene the graders render ------------------------------------------------------
@scene_builder
def week06_optics():
    """The graded render: a glass and a mirror ball before a floor and a wall, under a
    point light."""
    objects = [
        Quad(Vec3(-4, -0.5, -6), Vec3(8, 0, 0), Vec3(0, 0, 6), Lambertian(Color(0.6, 0.6, 0.6))),
        Quad(Vec3(-4, -0.5, -5), Vec3(8, 0, 0), Vec3(0, 4, 0), Lambertian(Color(0.3, 0.5, 0.7))),
        Sphere(Vec3(-0.7, 0.0, -2.2), 0.5, Dielectric(1.5)),
        Sphere(Vec3(0.7, 0.0, -2.6), 0.5, Mirror(Color(0.9, 0.9, 0.9))),
    ]
    camera = Camera(Vec3(0, 0.4, 0.5), Vec3(0, 0, -2.4), vfov=55, aspect_ratio="16:9", width=48)
    return Scene(objects, [PointLight(Vec3(0.5, 2.5, -1.0), Color(8, 8, 8))], camera=camera)
