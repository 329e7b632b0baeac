"""Week 07 probes: what the graders of test_week07.py (and the hidden checks) ask the
student's code, run in the student's process (see rtpy/grading/probes.py). Each takes
plain data, calls the week's task methods and returns plain data; the verdicts are
the graders'."""

from contextlib import nullcontext

import numpy as np

from rtpy import (
    Camera,
    CheckerTexture,
    Color,
    HitInfo,
    ImageTexture,
    Quad,
    Ray,
    Scene,
    Sphere,
    Vec3,
)
from rtpy.grading.probes import color, floats, probe, scene_builder, vec
from rtpy.grading.protocol import Array, List, Vec
from rtpy.materials import Lambertian, Metal
from rtpy.sampling import make_generator, use_generator

UV = List(Array((2,)))  # (u, v) per case


@probe(returns=UV)
def week07_sphere_surface_uv(cases: list):
    """Sphere(center, radius).surface_uv(hit) for each case {"center", "radius", "point",
    "normal"}: a hit on the sphere at point with that normal."""
    out = []
    for c in cases:
        sphere = Sphere(vec(c["center"]), float(c["radius"]), Lambertian())
        hit = HitInfo(vec(c["point"]), vec(c["normal"]), 1.0, True, sphere.material, sphere)
        out.append([float(x) for x in sphere.surface_uv(hit)])
    return out


@probe(returns=UV)
def week07_quad_surface_uv(cases: list):
    """Quad(q, u, v).surface_uv(hit) for each case {"q", "u", "v"} and either "point"
    (a hit there with the quad's normal) or "ray" [origin, direction] and "t" (the hit
    quad.hit_info(ray, t))."""
    out = []
    for c in cases:
        quad = Quad(vec(c["q"]), vec(c["u"]), vec(c["v"]), Lambertian())
        if "point" in c:
            hit = HitInfo(vec(c["point"]), quad.normal, 1.0, True, quad.material, quad)
        else:
            origin, direction = c["ray"]
            hit = quad.hit_info(Ray(vec(origin), vec(direction)), float(c["t"]))
        out.append([float(x) for x in quad.surface_uv(hit)])
    return out


@probe(returns=List(Vec))
def week07_checker_value(cases: list):
    """CheckerTexture(scale, even, odd).value(hit) for each case {"scale", "even", "odd",
    "point"}: a hit at point."""
    out = []
    for c in cases:
        texture = CheckerTexture(float(c["scale"]), color(c["even"]), color(c["odd"]))
        out.append(floats(texture.value(HitInfo(vec(c["point"]), Vec3(0, 1, 0), 1.0, True, None))))
    return out


@probe(returns=List(Vec))
def week07_image_texture_value(pixels, uv: list):
    """ImageTexture(pixels).value(hit) for each [u, v]: a hit whose (u, v) are given."""
    texture = ImageTexture(np.asarray(pixels, dtype=float))
    out = []
    for u, v in uv:
        hit = HitInfo(Vec3(0, 0, 0), Vec3(0, 1, 0), 1.0, True, None, None, float(u), float(v))
        out.append(floats(texture.value(hit)))
    return out


@probe(returns=List(Array((None, 7))))
def week07_metal_scatter(cases: list):
    """`count` calls of Metal(albedo, fuzz).scattering(ray, hit) for each case {"albedo",
    "fuzz", "origin", "direction": the incoming ray, "normal", "count", "generator"}: the
    hit at the origin of the world, rtpy's generator make_generator(*generator) (when
    not None). Per call: 1 and the direction and attenuation of the sample, or 0 (and
    zeros) for None."""
    out = []
    for c in cases:
        metal = Metal(color(c["albedo"]), float(c["fuzz"]))
        hit = HitInfo(Vec3(0, 0, 0), vec(c["normal"]), 1.0, True, metal)
        ray = Ray(vec(c["origin"]), vec(c["direction"]))
        rows = np.zeros((int(c["count"]), 7))
        generator = c["generator"]
        with use_generator(make_generator(*generator)) if generator else nullcontext():
            for k in range(len(rows)):
                s = metal.scattering(ray, hit)
                if s is not None:
                    rows[k] = [1.0, *floats(s.scattered_ray.direction), *floats(s.attenuation)]
        out.append(rows)
    return out


# --- the scene the graders render ------------------------------------------------------
@scene_builder
def week07_textures(pixels):
    """The graded render: a checker floor, an image-textured sphere and quad (the
    image's pixels given) under the sky."""
    checker = Lambertian(CheckerTexture(0.5, Color(0.9, 0.9, 0.9), Color(0.2, 0.3, 0.1)))
    image = Lambertian(ImageTexture(np.asarray(pixels, dtype=float)))
    objects = [
        Quad(Vec3(-4, -0.5, -6), Vec3(8, 0, 0), Vec3(0, 0, 6), checker),
        Sphere(Vec3(-0.7, 0.1, -2.2), 0.6, image),
        Quad(Vec3(0.2, -0.4, -2.5), Vec3(1.0, 0, 0.2), Vec3(0, 1.0, 0), image),
    ]
    camera = Camera(Vec3(0, 0.5, 0.5), Vec3(0, 0, -2.3), vfov=55, aspect_ratio="16:9", width=48)
    return Scene(objects, sky=True, camera=camera)
