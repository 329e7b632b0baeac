"""The "path" integrator: unbiased path tracing, against a closed form and against
its own variants (BRDF sampling alone, light sampling alone, both combined by MIS),
which estimate the same integral."""

from __future__ import annotations

import contextlib
import math
import statistics

import pytest

import rtpy
from rtpy import Camera, Color, RenderSettings, Scene, Sphere, Vec3
from rtpy.integrators import make_integrator
from rtpy.ray import Ray
from rtpy.sampling import make_generator, use_generator
from rtpy.testing.analytic_scenes import GlowingLambertian

from .estimates import box_scene, per_ray_z, z_limit


@pytest.mark.parametrize("nee", [True, False])
def test_furnace_inside_glowing_sphere_converges_to_le_over_one_minus_rho(nee):
    """Inside a closed sphere of albedo rho that emits Le, radiance is the same
    everywhere: L = Le + rho L, so L = Le / (1 - rho) = 1 for rho = Le = 0.5.
    The sphere is also an area light sampled from inside it, so this checks the
    area-to-solid-angle conversion and the MIS weights, with Russian roulette on."""
    rho, le = 0.5, 0.5
    sphere = Sphere(Vec3(0, 0, 0), 2.0, GlowingLambertian(Color(rho, rho, rho), Color(le, le, le)))
    scene = Scene([sphere])
    camera = Camera(Vec3(0.3, -0.2, 0.1), Vec3(0, 0, -1), vfov=100, aspect_ratio=1.0, width=12)
    image = rtpy.render(
        scene,
        camera=camera,
        integrator="path",
        nee=nee,
        spp=32,
        max_depth=200,
        russian_roulette=3,
        seed=11,
    )
    pixels = image.linear[..., 0].ravel()
    mean = pixels.mean()
    standard_error = pixels.std(ddof=1) / math.sqrt(pixels.size)
    assert standard_error > 0  # the estimate is noisy: the test measures that noise
    z = (mean - le / (1 - rho)) / standard_error
    assert abs(z) < z_limit(1), f"mean {mean:.5f} +- {standard_error:.5f}, z = {z:.2f}"


@pytest.mark.parametrize(
    "variant,n_variant,seeds",
    [
        pytest.param({"nee": False}, 4000, (100, 200), id="brdf-only", marks=pytest.mark.slow),
        pytest.param({"mis": False}, 1500, (300, 400), id="nee-only"),
    ],
)
def test_path_variants_agree_with_mis(variant, n_variant, seeds):
    """BRDF sampling alone (nee = false), light sampling alone (mis = false) and MIS
    estimate the same integral: per-ray means agree within the measured noise (the
    box scene has an area and a point light). Light counted twice (the course
    code's bug) or a wrong MIS weight would shift one of them."""
    scene, rays = box_scene()
    mis = make_integrator(RenderSettings(max_depth=5))
    other = make_integrator(RenderSettings(max_depth=5, **variant))
    limit = z_limit(len(rays))
    zs = per_ray_z(scene, rays, mis, other, 1500, n_variant, *seeds)
    for k, (z, m1, s1, m2, s2) in enumerate(zs):
        assert abs(z) < limit, f"ray {k}: mis {m1:.4f}+-{s1:.4f} vs {variant} {m2:.4f}+-{s2:.4f}"
        assert m2 > 0


@contextlib.contextmanager
def light_counted_twice():
    """A planted mistake while inside: emission found by BRDF sampling keeps weight 1
    although light sampling also counts it."""
    from rtpy.integrators import path

    original = path.emission_weight
    path.emission_weight = lambda *args: 1.0
    try:
        yield
    finally:
        path.emission_weight = original


@pytest.mark.slow
@pytest.mark.parametrize(
    "reference,n_reference,seed_reference,planted,n_planted,seed_planted",
    [({}, 1500, 300, {"mis": False}, 1500, 400), ({"nee": False}, 4000, 200, {}, 1500, 100)],
    ids=["nee-only-against-mis", "mis-against-brdf-only"],
)
def test_the_comparison_catches_light_counted_twice(
    reference, n_reference, seed_reference, planted, n_planted, seed_planted
):
    """The comparison above has power: light sampling alone, or MIS, that also adds
    the emission BRDF sampling finds with weight 1 (counting light twice) is rejected."""
    scene, rays = box_scene()
    good = make_integrator(RenderSettings(max_depth=5, **reference))
    bad = make_integrator(RenderSettings(max_depth=5, **planted))
    args = (n_reference, n_planted, seed_reference, seed_planted, light_counted_twice)
    zs = per_ray_z(scene, rays, good, bad, *args)
    assert max(abs(z[0]) for z in zs) > z_limit(len(rays))


@pytest.mark.parametrize("probability", [0.5, 0.9])
def test_fixed_roulette_in_glowing_sphere_converges_to_le_over_one_minus_rho(probability):
    """The lecture's fixed p_RR: inside the glowing sphere (L = Le / (1 - rho) = 1),
    paths that survive with probability p from segment 2 on and are divided by p have
    the exact mean, whatever p (z-test against the measured noise)."""
    rho, le = 0.5, 0.5
    sphere = Sphere(Vec3(0, 0, 0), 2.0, GlowingLambertian(Color(rho, rho, rho), Color(le, le, le)))
    settings = RenderSettings(
        integrator="path",
        max_depth=500,
        russian_roulette=2,
        roulette="fixed",
        roulette_probability=probability,
    )
    integrator = make_integrator(settings)
    ray = Ray(Vec3(0.3, -0.2, 0.1), Vec3(0.0, 0.6, -0.8))
    n = 3000
    with use_generator(make_generator(17)):
        samples = [integrator.compute_scattering(ray, Scene([sphere])).e0 for _ in range(n)]
    mean, se = statistics.fmean(samples), statistics.stdev(samples) / math.sqrt(n)
    assert se > 0
    assert abs(mean - le / (1 - rho)) < z_limit(2) * se, f"mean {mean:.5f} +- {se:.5f}"
