"""The graders in assignments/ pass on rtpy's solution and fail on classic mistakes.

Each planted mistake patches rtpy's solution with a buggy version (the course code's
own mistakes first: no 1/r^2, a cosine with the unnormalised vector to the light, a
shadow test that needs two blockers, no 1/pdf, albedo as the BRDF, light counted twice,
glass that never refracts, an unnormalised half vector) and shows that the graders
named with it fail, with a message. `python -m rtpy grade` is run on the reference for
every week in test_graders_pass_on_the_reference, which also checks the points table
and the Gradescope JSON.
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
import rtpy.integrators.direct_lighting as direct_lighting
import rtpy.integrators.path as path_module
import rtpy.materials.dielectric as dielectric
import rtpy.materials.glossy as glossy
import rtpy.materials.mirror as mirror
import rtpy.materials.phong as phong
import rtpy.vec3 as vec3
from rtpy import Camera, CheckerTexture, ImageTexture, PointLight, Quad, Ray, Scene, Sphere
from rtpy.grading import compare, render_stack, summarize
from rtpy.grading.assignment import WEEKS
from rtpy.io.cli import main
from rtpy.materials import CookTorrance, Lambertian, Metal, Phong
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
    def find_occlusion(self, ray, interval, brute_force=False, ignore=None):
        hits = sum(
            o is not ignore and o.hit_t(ray, interval.min, interval.max) is not None
            for o in self.objects
        )
        return hits > 1  # the course's "shadowed only if more than one object is hit"

    mp.setattr(Scene, "find_occlusion", find_occlusion)


def cosine_with_unnormalised_vector(mp):
    # The course code's cosine: the normal dotted with the vector to the light.
    plant(
        mp,
        direct_lighting,
        "sample_one_light",
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
    def find_intersection(self, ray, interval, brute_force=False):
        for obj in self.objects:
            t = obj.hit_t(ray, interval.min, interval.max)
            if t is not None:
                return obj.hit_info(ray, t)
        return None

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


# Week 8's mistakes, each one change to the solution's source, the course's own first:
# Phong's albedo as the BRDF (fr = kd + ks (R.V)^n) and the half vector (v + l) * 0.5.
WEEK08_MISTAKES = {
    "phong_albedo_as_brdf": (Phong, "BRDF", "* (self.kd * INV_PI)", "* self.kd"),
    "course_halfvector": (vec3, "halfvector", "unit_vector(view + light)", "(view + light) * 0.5"),
    "phong_wrong_normalisation": (Phong, "BRDF", "(n + 2.0) * INV_TWO", "(n + 1.0) * INV_TWO"),
    "phong_pdf_around_the_normal": (Phong, "pdf", "dot(mirror, wi)", "dot(normal, wi)"),
    "pdf_without_jacobian": (glossy, "reflected_density", " / (4.0 * wo_h)", ""),
    "pdf_without_cos_theta_h": (CookTorrance, "pdf", " * dot(normal, h)  #", "  #"),
    "mixture_pdf_unweighted": (glossy, "mixture_pdf", "(1.0 - p_diffuse) * ", ""),
    "cosine_power_wrong_inverse": (phong, "sample_cosine_power", "(exponent + 1", "(exponent + 2"),
    "ggx_without_pi": (CookTorrance, "D", "a2 / (math.pi * k * k)", "a2 / (k * k)"),
    "weight_without_1_over_pdf": (glossy, "weighted_sample", "* (cos_i / pdf)", "* cos_i"),
}
# the grader tests each must fail
WEEK08_FAILS = {
    "phong_albedo_as_brdf": ["test_phong_brdf"],
    "course_halfvector": ["test_blinn_phong_brdf"],
    "phong_wrong_normalisation": ["test_phong_brdf"],
    "phong_pdf_around_the_normal": ["test_pdf[phong]", "test_sampling_follows_pdf[phong]"],
    "pdf_without_jacobian": ["test_pdf[blinn_phong]", "test_sampling_follows_pdf[blinn_phong]"],
    "pdf_without_cos_theta_h": [
        "test_pdf[cook_torrance_ggx]",
        "test_sampling_follows_pdf[cook_torrance_ggx]",
    ],
    "mixture_pdf_unweighted": ["test_pdf[phong]", "test_sampling_follows_pdf[phong]"],
    "cosine_power_wrong_inverse": ["test_cosine_power_sampler"],
    "ggx_without_pi": [
        "test_cook_torrance_factors[ggx]",
        "test_cook_torrance_brdf[cook_torrance_ggx]",
    ],
    "weight_without_1_over_pdf": ["test_weight_is_brdf_cos_over_pdf[cook_torrance_ggx]"],
}


# (week, mistake, grader tests that must fail)
PLANTED = [
    ("03", cross_left_handed, ["test_cross_and_unit_vector"]),
    ("03", center_ray_through_corner, ["test_center_ray"]),
    ("03", jitter_outside_pixel, ["test_jittered_ray", "test_sky_render_matches_reference"]),
    ("03", unnormalised_camera_ray, ["test_center_ray", "test_jittered_ray"]),
    ("03", emitter_shows_albedo, ["test_flat_color"]),
    ("04", sphere_far_root, ["test_sphere_hit_t"]),
    ("04", sphere_ignores_t_min, ["test_sphere_hit_t"]),
    ("04", normal_not_flipped, ["test_sphere_hit_info"]),
    ("04", quad_no_interior_test, ["test_quad_hit", "test_center_render_matches_reference"]),
    ("04", first_hit_not_closest, ["test_closest_hit", "test_center_render_matches_reference"]),
    ("05", no_falloff, ["test_point_light_sample", "test_direct_light_on_a_plane_is_exact"]),
    ("05", unnormalised_light_vector, ["test_point_light_sample"]),
    ("05", cosine_with_unnormalised_vector, ["test_direct_light_on_a_plane_is_exact"]),
    ("05", two_blockers_needed, ["test_shadow_rays", "test_direct_light_on_a_plane_is_exact"]),
    ("05", albedo_as_brdf, ["test_lambertian_brdf_and_sampling"]),
    ("05", lambertian_no_pdf, ["test_lambertian_brdf_and_sampling"]),
    ("05", light_counted_twice, ["test_direct_render_matches_reference"]),
    ("06", reflect_wrong_sign, ["test_reflect", "test_mirror"]),
    ("06", schlick_power_four, ["test_schlick"]),
    ("06", no_total_internal_reflection, ["test_total_internal_reflection"]),
    ("06", glass_never_refracts, ["test_dielectric_reflects_with_probability_schlick"]),
    ("06", mirror_with_cosine, ["test_mirror"]),
    ("07", sphere_uv_from_plus_x, ["test_sphere_uv"]),
    ("07", checker_with_int, ["test_checker_texture"]),
    ("07", image_v_not_flipped, ["test_image_texture"]),
    ("07", fuzz_not_absorbed, ["test_metal_fuzz"]),
    ("07", fuzz_ignored, ["test_metal_fuzz"]),
    *[("08", in_source(k, *WEEK08_MISTAKES[k]), WEEK08_FAILS[k]) for k in WEEK08_MISTAKES],
    ("08", light_counted_twice, ["test_path_render_matches_reference"]),
    ("08", path_counts_light_twice, ["test_path_render_matches_reference", "test_path_furnace"]),
    ("08", roulette_not_divided, ["test_path_furnace"]),
]


def run_grader_test(week: str, name: str) -> None:
    """Call one grader test function (name[param] for a parametrized one)."""
    base, _, param = name.partition("[")
    fn = getattr(grader(week), base)
    if param:
        fn(param.rstrip("]"))
    else:
        fn()


@pytest.mark.parametrize(
    "week,mistake,graders", PLANTED, ids=[f"{w}-{m.__name__}" for w, m, _ in PLANTED]
)
def test_a_planted_mistake_fails_its_graders(monkeypatch, week, mistake, graders):
    mistake(monkeypatch)
    for name in graders:
        with pytest.raises(AssertionError) as info:
            run_grader_test(week, name)
        message = str(info.value)
        # where to look: a file, a Class.method or a function of rtpy, or the integrator
        assert re.search(r"rtpy/|[A-Z]\w*\.\w+|\w+ \(rtpy|integrator", message), (
            f"{name}: the message should say where to look: {message}"
        )


def test_every_week_has_planted_mistakes():
    assert {w for w, _, _ in PLANTED} == set(WEEKS)


@pytest.mark.slow
def test_graders_pass_on_the_reference(tmp_path, capsys):
    """`python -m rtpy grade WEEK --json` on rtpy's solution: full score, Gradescope format."""
    for week in WEEKS:
        out = tmp_path / f"results{week}.json"
        status = main(["grade", week, "--json", str(out)])
        table = capsys.readouterr().out
        results = json.loads(out.read_text())
        failed = [t for t in results["tests"] if t["score"] < t["max_score"]]
        assert status == 0 and not failed, f"week {week}: {failed}"
        assert (
            results["score"]
            == results["max_score"]
            == sum(t["max_score"] for t in results["tests"])
        )
        assert len(results["tests"]) >= 5
        for t in results["tests"]:
            assert set(t) == {"name", "score", "max_score", "output"} and t["max_score"] > 0
        assert "total" in table and f"{results['score']:g}/{results['max_score']:g}" in table


def test_noise_aware_comparison_accepts_noise_and_rejects_bias():
    """compare(): two independent renders of the same scene agree; 5 % more light does not."""
    scene = grader("05").area_light_scene()
    a = summarize(render_stack(scene, (1, 2, 3, 4), integrator="direct", spp=8), 8)
    b = summarize(render_stack(scene, (5, 6, 7, 8), integrator="direct", spp=8), 8)
    assert compare(a, b).passed
    brighter = dict(b, mean=b["mean"] * 1.05)
    assert not compare(a, brighter).passed


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
