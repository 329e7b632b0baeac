"""The graders in assignments/ pass on rtpy's solution and fail on classic mistakes.

Each planted mistake patches rtpy's solution with a buggy version (the course code's
own mistakes first: no 1/r^2, a cosine with the unnormalised vector to the light, a
shadow test that needs two blockers, no 1/pdf, albedo as the BRDF, light counted twice,
glass that never refracts, an unnormalised half vector), names the task of the week's
task map it belongs to, and shows that the graders named with it fail, with a message;
every task of every week has one, and the graders named include one of that task's.
`python -m rtpy grade` is run on the reference for every week in
test_graders_pass_on_the_reference, which also checks the table and the Gradescope
JSON (numbered task.test, named by the task's title).
"""

from __future__ import annotations

import importlib.util
import inspect
import json
import math
import re
import sys
import textwrap
from functools import cache
from pathlib import Path

import pytest

import rtpy.integrators.center as center
import rtpy.integrators.direct as direct
import rtpy.integrators.direct_lighting as direct_lighting
import rtpy.integrators.path as path_module
import rtpy.materials.dielectric as dielectric
import rtpy.materials.mirror as mirror
import rtpy.vec3 as vec3
from rtpy import (
    Camera,
    CheckerTexture,
    ImageTexture,
    Interval,
    PointLight,
    Quad,
    Ray,
    Scene,
    Sphere,
    Triangle,
)
from rtpy.cli.main import main
from rtpy.grading import compare, summarize
from rtpy.grading.assignment import WEEKS
from rtpy.grading.graders import collect_graders, local_probe
from rtpy.grading.sandbox import StudentError
from rtpy.grading.tasks import load_weeks
from rtpy.materials import BlinnPhong, CookTorrance, Lambertian, Metal, Phong, Ward
from rtpy.vec3 import Vec3

ROOT = Path(__file__).resolve().parents[2]


@cache
def grader(week: str):
    path = ROOT / "assignments" / f"week{week}" / f"test_week{week}.py"
    spec = importlib.util.spec_from_file_location(f"grader_week{week}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def wrap(cls, name, change):
    """cls.name replaced by a version that passes the original's result through change."""
    original = getattr(cls, name)

    def buggy(self, *args):
        return change(self, original(self, *args), *args)

    return buggy


def plant(mp, owner, name, old, new):
    """Replace owner.name by its own source with `old` changed to `new`: a mistake
    inside a function, such as a forgotten division. A module-level function is
    replaced in every rtpy module that imported it."""
    function = inspect.unwrap(getattr(owner, name))
    source = textwrap.dedent(inspect.getsource(function))
    assert old in source, f"{name}: {old!r} not in its source"
    namespace: dict = {}
    module_globals = vars(sys.modules[function.__module__])
    module_globals = {"dot": vec3.dot, **module_globals}
    exec(compile(source.replace(old, new), f"<planted {name}>", "exec"), module_globals, namespace)
    replace_everywhere(mp, owner, name, function, namespace[name])


def replace_everywhere(mp, owner, name, original, replacement):
    """owner.name = replacement, and the same in every rtpy module that holds original
    under that name (a module-level function imported by name)."""
    mp.setattr(owner, name, replacement)
    if inspect.ismodule(owner):
        for module_name, module in list(sys.modules.items()):
            if module_name.startswith("rtpy") and getattr(module, name, None) is original:
                mp.setattr(module, name, replacement)


# --- the mistakes -----------------------------------------------------------------------
def no_falloff(mp):
    def sample(self, p, original=PointLight.sample):
        s = original(self, p)
        s.radiance = self.intensity  # no 1/r^2
        return s

    mp.setattr(PointLight, "sample", sample)


def unnormalised_light_vector(mp):
    def sample(self, p, original=PointLight.sample):
        s = original(self, p)
        s.direction = s.direction * s.distance  # the vector to the light, not its direction
        return s

    mp.setattr(PointLight, "sample", sample)


def two_blockers_needed(mp):
    def find_occlusion(self, ray, interval, ignore=None):
        hits = sum(
            o is not ignore and o.hit_t(ray, interval.min, interval.max) is not None
            for o in self.objects
        )
        return hits > 1  # the course's "shadowed only if more than one object is hit"

    mp.setattr(Scene, "find_occlusion", find_occlusion)


def occlusion_by_the_bvh(mp):
    """find_occlusion answered by the given BVH's any_hit (the code above the stub)."""

    def find_occlusion(self, ray, interval, ignore=None):
        return self.bvh().any_hit(ray, interval.min, interval.max, ignore)

    mp.setattr(Scene, "find_occlusion", find_occlusion)


def lambertian_as_oren_nayar(mp):
    """Lambertian's three methods answered by the given OrenNayar with sigma = 0."""
    from rtpy.materials import OrenNayar

    def delegate(name):
        return lambda self, *args: getattr(OrenNayar(self.albedo, 0.0), name)(*args)

    for name in ("BRDF", "pdf", "scattering"):
        mp.setattr(Lambertian, name, delegate(name))


def cosine_with_unnormalised_vector(mp):
    # The course code's cosine: the normal dotted with the vector to the light.
    plant(
        mp,
        direct_lighting,
        "light_sample_estimate",
        "cos_i = abs(dot(normal, wi))",
        "d = sample.point - hit.point; cos_i = abs(dot(normal, d))",
    )


def roulette_not_divided(mp):
    plant(mp, path_module.PathIntegrator, "compute_scattering", "beta = beta / survive", "pass")


def path_counts_light_twice(mp):
    plant(
        mp,
        path_module.PathIntegrator,
        "compute_scattering",
        "result = result + beta * emitted * w",
        "result = result + beta * emitted",
    )


def path_right_on_average(mp):
    """compute_scattering times a random factor of mean 1: 0, or 50 with probability
    1/50. Unbiased and never negative, but with a huge variance."""
    from rtpy.sampling import generator

    def change(self, value, *args):
        return value * (50.0 if generator().random() < 0.02 else 0.0)

    cls = path_module.PathIntegrator
    mp.setattr(cls, "compute_scattering", wrap(cls, "compute_scattering", change))


def path_zero_mean_noise(mp):
    """compute_scattering plus zero-mean noise of standard deviation 30."""
    from rtpy.sampling import generator
    from rtpy.vec3 import Color

    def change(self, value, *args):
        noise = 30.0 * (1.0 if generator().random() < 0.5 else -1.0)
        return value + Color(noise, noise, noise)

    cls = path_module.PathIntegrator
    mp.setattr(cls, "compute_scattering", wrap(cls, "compute_scattering", change))


def albedo_as_brdf(mp):
    mp.setattr(Lambertian, "BRDF", wrap(Lambertian, "BRDF", lambda self, f, *a: f * math.pi))


def lambertian_no_pdf(mp):
    def change(self, s, ray_in, hit):
        if s is not None:
            cos = vec3.dot(s.scattered_ray.direction, hit.normal)
            s.attenuation = self.albedo.value(hit) * (cos / math.pi)  # BRDF * cos, no 1/pdf
        return s

    mp.setattr(Lambertian, "scattering", wrap(Lambertian, "scattering", change))


def light_counted_twice(mp):
    mp.setattr(direct_lighting, "emission_weight", lambda *args: 1.0)
    mp.setattr(path_module, "emission_weight", lambda *args: 1.0)


def center_ray_through_corner(mp):
    mp.setattr(Camera, "get_center_ray", lambda self, i, j: self._ray_through(i + 0.5, j + 0.5))


def jitter_outside_pixel(mp):
    from rtpy.sampling import generator

    def get_ray(self, i, j):
        r = generator().random
        return self._ray_through(i + r(), j + r())  # [0, 1) around the center: off by half

    mp.setattr(Camera, "get_ray", get_ray)


def unnormalised_camera_ray(mp):
    def change(self, ray, *args):
        return Ray(ray.origin, ray.direction * 3.0)

    mp.setattr(Camera, "_ray_through", wrap(Camera, "_ray_through", change))


def emitter_shows_albedo(mp):
    def flat_color(ray, scene):
        hit = scene.find_intersection(ray, None)
        if hit is None:
            return scene.background_radiance(ray.direction)
        return hit.material.flat_color(hit)

    mp.setattr(center, "flat_color", flat_color)


def cross_left_handed(mp):
    original = vec3.cross
    mp.setattr(vec3, "cross", lambda a, b: original(b, a))


def sphere_far_root(mp):
    def hit_t(self, ray, t_min, t_max, original=Sphere.hit_t):
        t = original(self, ray, t_min, t_max)
        if t is None:
            return None
        far = original(self, ray, t + 1e-9, t_max)
        return far if far is not None else t

    mp.setattr(Sphere, "hit_t", hit_t)


def sphere_ignores_t_min(mp):
    mp.setattr(
        Sphere, "hit_t", lambda self, ray, t_min, t_max, o=Sphere.hit_t: o(self, ray, -1e9, t_max)
    )


def normal_not_flipped(mp):
    def change(self, hit, ray, t):
        c = self.center
        hit.normal = (hit.point - c) / self.radius
        return hit

    mp.setattr(Sphere, "hit_info", wrap(Sphere, "hit_info", change))


def quad_no_interior_test(mp):
    def hit_t(self, ray, t_min, t_max):
        denom = vec3.dot(self.normal, ray.direction)
        if denom == 0.0:
            return None
        t = (self.d - vec3.dot(self.normal, ray.origin)) / denom
        return t if t_min < t < t_max else None

    mp.setattr(Quad, "hit_t", hit_t)


def first_hit_not_closest(mp):
    def find_intersection(self, ray, interval):
        for obj in self.objects:
            t = obj.hit_t(ray, interval.min, interval.max)
            if t is not None:
                return obj.hit_info(ray, t)
        return None

    mp.setattr(Scene, "find_intersection", find_intersection)


def closest_hit_by_the_bvh(mp):
    """find_intersection answered by the given BVH (the code above the stub)."""

    def find_intersection(self, ray, interval):
        return self.bvh().find_intersection(ray, interval)

    mp.setattr(Scene, "find_intersection", find_intersection)


def reflect_wrong_sign(mp):
    def reflect(v, n):
        k = 2.0 * vec3.dot(v, n)
        return Vec3(v.e0 + k * n.e0, v.e1 + k * n.e1, v.e2 + k * n.e2)

    for module in (vec3, mirror, dielectric):
        mp.setattr(module, "reflect", reflect)


def glass_never_refracts(mp):
    def scattering(self, ray_in, hit):
        _, reflected, _ = self._split(ray_in, hit)
        return dielectric.ScatterInfo(reflected, self.albedo.value(hit), 0.0, True)

    mp.setattr(dielectric.Dielectric, "scattering", scattering)


def schlick_power_four(mp):
    def schlick(cosine, ratio):
        r0 = ((1.0 - ratio) / (1.0 + ratio)) ** 2
        return r0 + (1.0 - r0) * (1.0 - cosine) ** 4

    mp.setattr(dielectric, "schlick", schlick)


def no_total_internal_reflection(mp):
    def split(self, ray_in, hit):
        ratio = 1.0 / self.ior if hit.front_face else self.ior
        d, n = ray_in.direction, hit.normal
        cos = min(-vec3.dot(d, n), 1.0)
        spawn = dielectric.spawn_ray
        return (
            dielectric.schlick(cos, ratio),
            spawn(hit.point, n, vec3.reflect(d, n)),
            spawn(hit.point, n, vec3.refract(d, n, ratio)),
        )

    mp.setattr(dielectric.Dielectric, "_split", split)


def mirror_with_cosine(mp):
    def change(self, s, ray_in, hit):
        s.attenuation = s.attenuation * abs(vec3.dot(s.scattered_ray.direction, hit.normal))
        return s

    mp.setattr(mirror.Mirror, "scattering", wrap(mirror.Mirror, "scattering", change))


def image_v_not_flipped(mp):
    def value(self, hit):
        i = min(int(hit.u * self.width), self.width - 1)
        j = min(int(hit.v * self.height), self.height - 1)  # v = 0 at the top: upside down
        return self._rows[j][i]

    mp.setattr(ImageTexture, "value", value)


def checker_with_int(mp):
    def value(self, hit):
        p, k = hit.point, self.inv_scale
        cell = int(p.e0 * k) + int(p.e1 * k) + int(p.e2 * k)  # int rounds toward 0
        return self.even if cell % 2 == 0 else self.odd

    mp.setattr(CheckerTexture, "value", value)


def sphere_uv_from_plus_x(mp):
    def change(self, uv, hit):
        return (uv[0] + 0.5) % 1.0, uv[1]

    mp.setattr(Sphere, "surface_uv", wrap(Sphere, "surface_uv", change))


def fuzz_not_absorbed(mp):
    from rtpy.sampling import random_unit_vector

    def scattering(self, ray_in, hit):
        d = vec3.unit_vector(
            vec3.reflect(ray_in.direction, hit.normal) + random_unit_vector() * self.fuzz
        )
        return dielectric.ScatterInfo(Ray(hit.point, d), self.albedo.value(hit), 0.0, True)

    mp.setattr(Metal, "scattering", scattering)


def fuzz_ignored(mp):
    def scattering(self, ray_in, hit):
        d = vec3.reflect(ray_in.direction, hit.normal)
        return dielectric.ScatterInfo(Ray(hit.point, d), self.albedo.value(hit), 0.0, True)

    mp.setattr(Metal, "scattering", scattering)


def in_source(label, owner, name, old, new):
    """The mistake `label`: `old` changed to `new` in the source of owner.name (plant)."""

    def mistake(mp):
        plant(mp, owner, name, old, new)

    mistake.__name__ = label
    return mistake


def interval_contains_open(mp):
    mp.setattr(Interval, "contains", lambda self, x: self.min < x < self.max)


def refract_inverted_ratio(mp):
    original = vec3.refract
    mp.setattr(vec3, "refract", lambda uv, n, eta: original(uv, n, 1.0 / eta))


def weight_without_1_over_pdf(cls):
    """scattering() of cls with the weight BRDF * cos (times pdf / pdf forgotten)."""

    def mistake(mp):
        def change(self, s, ray_in, hit):
            if s is not None:
                s.attenuation = s.attenuation * s.pdf
            return s

        mp.setattr(cls, "scattering", wrap(cls, "scattering", change))

    mistake.__name__ = f"{cls.__name__.lower()}_weight_without_1_over_pdf"
    return mistake


# Mistakes inside a function: (owner, name, the solution's text, the mistake's).
LIGHT_SAMPLE = (direct_lighting, "light_sample_estimate")
DIRECT = (direct.DirectIntegrator, "compute_scattering")
SOURCE_MISTAKES = {
    "triangle_as_parallelogram": (Triangle, "_barycentric", "u + v > 1.0", "v > 1.0"),
    "lambertian_pdf_uniform": (Lambertian, "pdf", ") * INV_PI", ") * 0.0 + 0.5 * INV_PI"),
    "estimate_without_1_over_pdf": (*LIGHT_SAMPLE, "(cos_i / sample.pdf)", "cos_i"),
    "shadow_ray_blocked_by_its_light": (*LIGHT_SAMPLE, "ignore=light_shape", "ignore=None"),
    "shadow_ray_without_offset": (
        *LIGHT_SAMPLE,
        "spawn_ray(hit.point, normal, wi)",
        "Ray(hit.point, wi)",
    ),
    "direct_without_emission": (*DIRECT, "emitted + direct_lighting(", "direct_lighting("),
    "quad_uv_swapped": (Quad, "surface_uv", "a, b = self._coords", "b, a = self._coords"),
    "phong_albedo_as_brdf": (Phong, "BRDF", "* (self.kd * INV_PI)", "* self.kd"),
    "phong_wrong_normalisation": (Phong, "BRDF", "(n + 2.0) * INV_TWO", "(n + 1.0) * INV_TWO"),
    "phong_pdf_around_the_normal": (Phong, "pdf", "dot(mirror, wi)", "dot(normal, wi)"),
    "phong_pdf_without_diffuse": (Phong, "pdf", "(diffuse_probability(self, hit),", "(0.0,"),
    "phong_highlight_around_the_normal": (Phong, "scattering", "ONB(mirror)", "ONB(hit.normal)"),
    "course_halfvector": (BlinnPhong, "BRDF", "halfvector(wo, wi)", "(wo + wi) * 0.5"),
    "blinn_without_jacobian": (
        BlinnPhong,
        "pdf",
        "reflected_density(density_h, wo, h)",
        "density_h",
    ),
    "blinn_half_vector_as_wi": (BlinnPhong, "scattering", "reflect(ray_in.direction, h)", "h"),
    "cook_torrance_pdf_without_cos_theta_h": (CookTorrance, "pdf", " * dot(normal, h)  #", "  #"),
    "cook_torrance_without_masking": (CookTorrance, "BRDF", "self.G1(normal, wi)", "1.0"),
    "ward_without_jacobian": (Ward, "pdf", "reflected_density(density_h, wo, h)", "density_h"),
}


def source(label):
    """The mistake `label` of SOURCE_MISTAKES."""
    return in_source(label, *SOURCE_MISTAKES[label])


# (task, mistake, grader tests that must fail; one of them the task's own)
PLANTED = [
    ("03.1", cross_left_handed, ["test_cross_and_unit_vector"]),
    ("03.2", interval_contains_open, ["test_interval"]),
    ("03.3", center_ray_through_corner, ["test_center_ray"]),
    ("03.3", unnormalised_camera_ray, ["test_center_ray", "test_jittered_ray"]),
    ("03.4", emitter_shows_albedo, ["test_flat_color"]),
    ("03.5", jitter_outside_pixel, ["test_jittered_ray", "test_sky_render_matches_reference"]),
    ("04.1", sphere_far_root, ["test_sphere_hit_t"]),
    ("04.1", sphere_ignores_t_min, ["test_sphere_hit_t"]),
    ("04.1", normal_not_flipped, ["test_sphere_hit_info"]),
    ("04.2", quad_no_interior_test, ["test_quad_hit", "test_center_render_matches_reference"]),
    ("04.3", source("triangle_as_parallelogram"), ["test_triangle_hit"]),
    ("04.4", first_hit_not_closest, ["test_closest_hit", "test_center_render_matches_reference"]),
    ("04.4", closest_hit_by_the_bvh, ["test_closest_hit"]),
    ("05.1", no_falloff, ["test_point_light_sample", "test_direct_light_on_a_plane_is_exact"]),
    ("05.1", unnormalised_light_vector, ["test_point_light_sample"]),
    ("05.2", two_blockers_needed, ["test_shadow_rays", "test_direct_light_on_a_plane_is_exact"]),
    ("05.2", occlusion_by_the_bvh, ["test_shadow_rays"]),
    ("05.3", albedo_as_brdf, ["test_lambertian_brdf_and_sampling"]),
    ("05.3", lambertian_as_oren_nayar, ["test_lambertian_brdf_and_sampling"]),
    ("05.3", lambertian_no_pdf, ["test_lambertian_brdf_and_sampling"]),
    ("05.3", source("lambertian_pdf_uniform"), ["test_lambertian_brdf_and_sampling"]),
    (
        "05.4",
        cosine_with_unnormalised_vector,
        ["test_light_sample_estimate", "test_direct_light_on_a_plane_is_exact"],
    ),
    (
        "05.4",
        source("estimate_without_1_over_pdf"),
        ["test_light_sample_estimate", "test_direct_render_matches_reference"],
    ),
    ("05.4", source("shadow_ray_blocked_by_its_light"), ["test_light_sample_estimate"]),
    ("05.4", source("shadow_ray_without_offset"), ["test_direct_render_matches_reference"]),
    (
        "05.4",
        source("direct_without_emission"),
        ["test_direct_sees_emitters_and_background", "test_direct_render_matches_reference"],
    ),
    ("05.4", light_counted_twice, ["test_direct_render_matches_reference"]),
    ("06.1", reflect_wrong_sign, ["test_reflect", "test_mirror"]),
    ("06.1", mirror_with_cosine, ["test_mirror"]),
    ("06.2", refract_inverted_ratio, ["test_refract_obeys_snell"]),
    ("06.3", schlick_power_four, ["test_schlick"]),
    ("06.3", no_total_internal_reflection, ["test_total_internal_reflection"]),
    ("06.3", glass_never_refracts, ["test_dielectric_reflects_with_probability_schlick"]),
    ("07.1", sphere_uv_from_plus_x, ["test_sphere_uv"]),
    ("07.1", source("quad_uv_swapped"), ["test_quad_uv"]),
    ("07.2", checker_with_int, ["test_checker_texture"]),
    ("07.2", image_v_not_flipped, ["test_image_texture"]),
    ("07.3", fuzz_not_absorbed, ["test_metal_fuzz"]),
    ("07.3", fuzz_ignored, ["test_metal_fuzz"]),
    # Week 8, each a change to the solution's source, the course's own first: Phong's
    # albedo as the BRDF (fr = kd + ks (R.V)^n) and the half vector (v + l) * 0.5.
    ("08.1", source("phong_albedo_as_brdf"), ["test_phong_brdf"]),
    ("08.1", source("phong_wrong_normalisation"), ["test_phong_brdf"]),
    (
        "08.1",
        source("phong_pdf_around_the_normal"),
        ["test_pdf[phong]", "test_sampling_follows_pdf[phong]"],
    ),
    (
        "08.1",
        source("phong_pdf_without_diffuse"),
        ["test_pdf[phong]", "test_sampling_follows_pdf[phong]"],
    ),
    ("08.1", source("phong_highlight_around_the_normal"), ["test_sampling_follows_pdf[phong]"]),
    ("08.1", weight_without_1_over_pdf(Phong), ["test_weight_is_brdf_cos_over_pdf[phong]"]),
    ("08.2", source("course_halfvector"), ["test_blinn_phong_brdf"]),
    (
        "08.2",
        source("blinn_without_jacobian"),
        ["test_pdf[blinn_phong]", "test_sampling_follows_pdf[blinn_phong]"],
    ),
    ("08.2", source("blinn_half_vector_as_wi"), ["test_sampling_follows_pdf[blinn_phong]"]),
    (
        "08.3",
        source("cook_torrance_pdf_without_cos_theta_h"),
        ["test_pdf[cook_torrance_ggx]", "test_sampling_follows_pdf[cook_torrance_ggx]"],
    ),
    (
        "08.3",
        source("cook_torrance_without_masking"),
        ["test_cook_torrance_brdf[cook_torrance_ggx]"],
    ),
    (
        "08.3",
        weight_without_1_over_pdf(CookTorrance),
        ["test_weight_is_brdf_cos_over_pdf[cook_torrance_ggx]"],
    ),
    ("08.4", light_counted_twice, ["test_path_render_matches_reference"]),
    ("08.4", path_counts_light_twice, ["test_path_render_matches_reference", "test_path_furnace"]),
    ("08.4", roulette_not_divided, ["test_path_furnace"]),
    (
        "08.4",
        path_right_on_average,
        [
            "test_path_render_matches_reference",
            "test_path_furnace",
            "hidden/test_path_furnace_at_new_seeds",
        ],
    ),
    ("08.4", path_zero_mean_noise, ["test_path_furnace", "hidden/test_path_furnace_at_new_seeds"]),
    (
        "08.5",
        source("ward_without_jacobian"),
        ["test_pdf[ward]", "test_sampling_follows_pdf[ward]"],
    ),
]


@cache
def probe_of(week: str):
    """The graders' probe, answered in this process: planted mistakes patch rtpy here."""
    return local_probe(week, ROOT, in_process=True)


@cache
def hidden_grader(week: str):
    path = ROOT / "assignments" / f"week{week}" / "hidden" / f"test_week{week}_hidden.py"
    spec = importlib.util.spec_from_file_location(f"hidden_grader_week{week}", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def run_grader_test(week: str, name: str) -> None:
    """Call one grader test function (name[param] for a parametrized one; hidden/name
    for a hidden check)."""
    base, _, param = name.partition("[")
    module = grader(week)
    if base.startswith("hidden/"):
        module, base = hidden_grader(week), base.removeprefix("hidden/")
    fn = getattr(module, base)
    if param:
        fn(param.rstrip("]"), probe=probe_of(week))
    else:
        fn(probe=probe_of(week))


@pytest.mark.parametrize(
    "task,mistake,graders", PLANTED, ids=[f"{t}-{m.__name__}" for t, m, _ in PLANTED]
)
@pytest.mark.slow
def test_a_planted_mistake_fails_its_graders(monkeypatch, task, mistake, graders):
    mistake(monkeypatch)
    for name in graders:
        with pytest.raises((AssertionError, StudentError)) as info:  # a verdict or a refusal
            run_grader_test(task[:2], name)
        message = str(info.value)
        # where to look: a file, a Class.method or a function of rtpy, or the integrator
        assert re.search(r"rtpy/|[A-Z]\w*\.\w+|\w+ \(rtpy|integrator", message), (
            f"{name}: the message should say where to look: {message}"
        )


@cache
def graders_by_name(week: str) -> dict[str, str | None]:
    """Grader test name (with its case) -> the task it grades, collected by pytest."""
    return {g.nodeid.split("::")[-1]: g.task for g in collect_graders(week)}


def plant_problems(planted, weeks, graders_of) -> list[str]:
    """What is wrong with the planted mistakes against the task maps: a task without a
    mistake, a mistake naming no grader of its task or a grader that does not exist."""
    problems = []
    tasks = {t.id for w in weeks for t in w.tasks}
    for task, mistake, names in planted:
        graders = graders_of(task[:2])
        missing = [n for n in names if n not in graders and not n.startswith("hidden/")]
        if task not in tasks or missing:
            problems.append(f"{task} {mistake.__name__}: no such task or graders {missing}")
        elif not any(graders[n] == task for n in names):
            problems.append(f"{task} {mistake.__name__}: names no grader of task {task}")
    planted_tasks = {t for t, _, _ in planted}
    problems += [f"{t}: no planted mistake" for t in sorted(tasks - planted_tasks)]
    return problems


def test_every_task_has_a_planted_mistake_that_its_graders_catch():
    """Every task of every week's map (extensions too) has a planted mistake above,
    and each mistake names a grader of its own task among those that must fail."""
    weeks = load_weeks(ROOT)
    assert {w.week for w in weeks} == set(WEEKS)
    assert plant_problems(PLANTED, weeks, graders_by_name) == []
    # the check can fail: a task without a mistake, and a mistake on another task's grader
    cut = [p for p in PLANTED if p[0] != "05.2"]
    moved = [("05.1", two_blockers_needed, ["test_shadow_rays"])]
    assert plant_problems(cut + moved, weeks, graders_by_name) == [
        "05.1 two_blockers_needed: names no grader of task 05.1",
        "05.2: no planted mistake",
    ]


@pytest.mark.slow
def test_graders_pass_on_the_reference(tmp_path, capsys):
    """`python -m rtpy grade WEEK --json` on rtpy's solution: full score, every test
    passed (the extensions' too), numbered task.test and named by its task's title in
    the task map's order, the points per task those of the map, a subtotal per task."""
    for week_map in load_weeks(ROOT):
        week = week_map.week
        out = tmp_path / f"results{week}.json"
        status = main(["grade", week, "--json", str(out)])
        table = capsys.readouterr().out
        results = json.loads(out.read_text())
        failed = [t for t in results["tests"] if t["status"] != "passed"]
        assert status == 0 and not failed, f"week {week}: {failed}"
        assert (
            results["score"]
            == results["max_score"]
            == sum(t["max_score"] for t in results["tests"])
            == sum(t.points for t in week_map.graded)
        )
        keys = {"name", "number", "score", "max_score", "status", "output", "visibility"}
        numbers = [t["number"] for t in results["tests"]]
        for task in week_map.tasks:
            tests = [t for t in results["tests"] if t["number"].startswith(f"{task.number}.")]
            assert [t["number"] for t in tests] == [
                f"{task.number}.{k + 1}" for k in range(len(tests))
            ]
            assert tests and sum(t["max_score"] for t in tests) == task.points, task.id
            assert all(set(t) == keys and t["name"].startswith(f"{task.title}: ") for t in tests)
            got = f"{task.number} {task.title}"
            assert any(line.startswith(got) for line in table.splitlines()), (got, table)
        assert len(numbers) == len(set(numbers)) == len(results["tests"]) >= 5
        assert "total" in table and f"{results['score']:g}/{results['max_score']:g}" in table


def test_noise_aware_comparison_accepts_noise_and_rejects_bias():
    """compare(): two independent renders of the same scene agree; 5 % more light does not."""
    probe, settings = probe_of("05"), {"integrator": "direct", "spp": 8}
    a = summarize(probe.render(scene="area_light", seeds=[1, 2, 3, 4], settings=settings), 8)
    b = summarize(probe.render(scene="area_light", seeds=[5, 6, 7, 8], settings=settings), 8)
    assert compare(a, b).passed
    brighter = dict(b, mean=b["mean"] * 1.05)
    assert not compare(a, brighter).passed


def reference_like(reference: dict, spp: int, renders: int, rng, spread: float = 1.0):
    """`renders` simulated renders at spp with the reference's mean and `spread` times
    its noise, never negative: each pixel a gamma variable of that mean and variance."""
    import numpy as np

    mean, var = reference["mean"], (spread**2) * reference["s2"] / spp
    lit = (mean > 0) & (var > 0)
    shape = np.where(lit, mean**2 / np.where(lit, var, 1.0), 1.0)
    scale = np.where(lit, var / np.where(lit, mean, 1.0), 0.0)
    return np.stack([np.where(lit, rng.gamma(shape, scale), mean) for _ in range(renders)])


NOISY_REFERENCES = [("05", "direct_area_light"), ("08", "path_three_balls")]


def render_reference(week: str, name: str) -> dict:
    from rtpy.grading.graders import load_reference

    return load_reference(ROOT / f"assignments/week{week}/reference/{name}.npz")


@pytest.mark.parametrize("week, name", NOISY_REFERENCES)
def test_the_render_verdict_passes_the_reference_noise(week, name):
    """assert_render_matches: renders right on average with the reference's noise pass
    (of 300 sets, at most 3 fail: ALPHA = 1e-3 makes 0.3 expected, and more than 3 has
    probability 4e-4)."""
    import numpy as np

    from rtpy.grading.graders import assert_render_matches

    reference, spp, renders = render_reference(week, name), 8, 4  # the graders' settings
    rng = np.random.default_rng(4408)
    failed = 0
    for _ in range(300):
        try:
            assert_render_matches(reference_like(reference, spp, renders, rng), spp, reference, "x")
        except AssertionError:
            failed += 1
    assert failed <= 3, f"{failed} of 300 correct renders failed"


@pytest.mark.parametrize("week, name", NOISY_REFERENCES)
def test_the_render_verdict_fails_huge_zero_mean_noise(week, name):
    """Renders right on average but 10 times noisier than the reference (a weight that
    is huge where it should be small) fail every time, though their own spread would
    mostly excuse them; the message says they are too noisy."""
    import numpy as np

    from rtpy.grading.graders import assert_render_matches

    reference, spp, renders = render_reference(week, name), 8, 4
    rng = np.random.default_rng(4409)
    for _ in range(20):
        noisy = reference_like(reference, spp, renders, rng, spread=10.0)
        with pytest.raises(AssertionError, match="times as noisy as the reference"):
            assert_render_matches(noisy, spp, reference, "huge zero-mean noise")


def test_graders_that_cannot_load_score_zero(tmp_path, capsys, monkeypatch):
    """A grader folder whose module fails to import (a syntax error in rtpy, say)
    gives score 0 with the error, and exit status 1 — never 0 of 0 as a pass."""
    folder = tmp_path / "assignments" / "week05"
    folder.mkdir(parents=True)
    (folder / "test_broken_grader.py").write_text("import rtpy.no_such_module\n")
    monkeypatch.chdir(tmp_path)
    out = tmp_path / "r.json"
    assert main(["grade", "05", "--json", str(out)]) == 1
    results = json.loads(out.read_text())
    assert results["score"] == 0 and "no_such_module" in results["output"]
    assert "could not be loaded" in capsys.readouterr().out


def test_shadow_acne_is_blamed_on_the_missing_spawn_ray(monkeypatch):
    """A shadow ray that leaves from the hit point itself (no offset) darkens lit
    surfaces with acne: the render grader's message names spawn_ray."""
    source("shadow_ray_without_offset")(monkeypatch)
    with pytest.raises(AssertionError, match=r"spawn_ray\(hit.point, hit.normal, direction\)"):
        run_grader_test("05", "test_direct_render_matches_reference")


def test_a_failed_chi_square_grader_draws_its_picture_locally(monkeypatch, tmp_path):
    """Phong's highlight drawn around the normal: in a local run (PICTURES set by
    grade()) the sampling grader draws the check and names the file; elsewhere (the
    autograder, plain pytest) its message says how to get the picture."""
    import rtpy.grading.graders as graders

    source("phong_highlight_around_the_normal")(monkeypatch)
    with pytest.raises(AssertionError, match=r"python -m rtpy grade 08.* rtpy-checks/week08"):
        run_grader_test("08", "test_sampling_follows_pdf[phong]")
    monkeypatch.setattr(graders, "PICTURES", tmp_path / "rtpy-checks")
    with pytest.raises(AssertionError) as info:
        run_grader_test("08", "test_sampling_follows_pdf[phong]")
    drawn = list((tmp_path / "rtpy-checks").glob("week08-Phong-*.png"))
    assert len(drawn) == 1 and f"Picture of this check: {drawn[0].as_posix()}" in str(info.value)


@pytest.mark.parametrize(
    "label,blamed,spared",
    [
        ("phong_pdf_around_the_normal", "pdf()", "BRDF()"),
        ("phong_wrong_normalisation", "BRDF()", "pdf()"),
    ],
)
def test_a_wrong_weight_names_the_method_that_makes_it_wrong(monkeypatch, label, blamed, spared):
    """The weights of weighted_sample are BRDF * cos / pdf of the student's own methods:
    when they differ from the model's, the message names the one that differs there."""
    source(label)(monkeypatch)
    with pytest.raises(AssertionError) as info:
        run_grader_test("08", "test_weight_is_brdf_cos_over_pdf[phong]")
    message = str(info.value)
    assert f"your {blamed} differs from the model" in message and f"your {spared}" not in message
