"""MaterialTable against the scalar materials, for every kind of material.

- BRDF and pdf equal the scalar methods on random hits (random normals and tangents,
  also off the surface and along the normal, viewers and light directions at grazing
  angles, below the surface and along the mirror direction, random parameters and
  textured albedos): bit for bit, but where the glossy models call pow, exp or log1p,
  whose numpy and C library versions round differently, to LIBM_REL (kernel_checks.py).
  flat_color and emitting are equal bit for bit, specular_rays to LIBM_REL.
- scattering: fed the uniform numbers the kernel drew, the scalar scattering() gives
  the same samples (with the scalar local samplers; theirs are compared in the models'
  test files); every live sample's weight is f cos / pdf and its pdf is pdf() at its
  direction; the directions follow that pdf (rtpy.testing's chi2 test); and the
  absorbed fraction and the mean weight (the directional albedo) agree with the scalar
  sampler's by z-tests with fixed seeds.
- kernels are chosen by the name a material's own class declares (every scene
  material and GlowingLambertian has one; a subclass, an unknown or odd name, gets the
  fallback), and the number of kernel and numpy calls does
  not grow with the number of materials.
"""

from __future__ import annotations

import gc
import sys

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rtpy.materials import MATERIALS as SCENE_MATERIALS
from rtpy.materials import CookTorrance, Dielectric, Lambertian, Material, Metal, Phong
from rtpy.numpy_backend.materials import KERNELS, MaterialTable, class_name, kernel_class
from rtpy.numpy_backend.materials.fallback import ScalarFallback
from rtpy.testing import chi2_test
from rtpy.vec3 import Color

from .kernel_checks import (
    CHI2_ALPHA,
    LIBM_KINDS,
    LIBM_REL,
    MATERIALS,
    NON_SPECULAR,
    SAMPLING_CASES,
    assert_agrees,
    check_brdf_and_pdf,
    check_samples_match_brdf_and_pdf,
    compare_with_scalar_sampler,
    head,
    random_hits,
    random_table,
    random_wi,
    scalar_hit,
    scalar_per_hit,
    seeds,
)
from .sampler_checks import check_scattering_equals_scalar, use_scalar_local_samplers


@pytest.mark.parametrize("kind", list(MATERIALS))
@settings(max_examples=20)
@given(data=st.data(), seed=seeds)
def test_brdf_and_pdf_equal_scalar(kind, data, seed):
    table, ids, hits, rng = random_table(data, kind, seed, 150)
    assert {type(k) for k in table.kernels}.isdisjoint({ScalarFallback})
    rel = LIBM_REL if kind in LIBM_KINDS else 0.0
    check_brdf_and_pdf(table, ids, hits, random_wi(rng, hits), rel)


class Grey(Lambertian):
    """A student's subclass: dispatched to the scalar fallback, whatever it inherits."""

    def BRDF(self, ray_view, ray_light, hit):
        return super().BRDF(ray_view, ray_light, hit) * 0.5


@settings(max_examples=15)
@given(data=st.data(), seed=seeds)
def test_mixed_table_equals_scalar(data, seed):
    """Any mix of kinds (and a fallback) in one table: BRDF, pdf, flat_color, emitting."""
    kinds = st.sampled_from(list(MATERIALS)).flatmap(lambda k: MATERIALS[k])
    materials = data.draw(st.lists(kinds, min_size=1, max_size=12))
    materials.append(Grey(Color(0.2, 0.4, 0.6)))
    rng = np.random.default_rng(seed)
    hits = random_hits(rng, 300)
    ids = rng.integers(len(materials), size=300)
    table = MaterialTable(materials)
    check_brdf_and_pdf(table, ids, hits, random_wi(rng, hits))
    flat = scalar_per_hit("flat_color", materials, ids, hits)
    np.testing.assert_array_equal(table.flat_color(ids, hits), flat)
    emitted = scalar_per_hit("emitting", materials, ids, hits)
    np.testing.assert_array_equal(table.emitting(ids, hits), emitted)
    np.testing.assert_array_equal(table.is_specular, [m.is_specular for m in materials])
    np.testing.assert_array_equal(table.is_emitter, [m.is_emitter for m in materials])


def test_an_empty_batch():
    table = MaterialTable([Lambertian(), Phong(ks=0.5)])
    hits = random_hits(np.random.default_rng(0), 0)
    ids, wi = np.zeros(0, int), np.zeros((0, 3))
    assert table.BRDF(ids, hits, wi).shape == (0, 3) and table.pdf(ids, hits, wi).shape == (0,)
    assert len(table.scattering(ids, hits, np.random.default_rng(0))) == 0


@settings(max_examples=10)
@given(data=st.data(), seed=seeds)
def test_specular_rays_equal_scalar(data, seed):
    """The Whitted rays of mixed tables. The refracted ray's weight is albedo (1 - R):
    near grazing incidence R is close to 1, so its ulp-level rounding (numpy's
    vectorized pow and the C library's pow round (1 - cos)^5 differently in the last
    bit) is magnified by the cancellation, in both backends alike. That weight can
    agree only relative to what was subtracted from: to LIBM_REL of the albedo."""
    kinds = st.sampled_from(["mirror", "metal", "dielectric", "lambertian", "phong"])
    materials = data.draw(st.lists(kinds.flatmap(lambda k: MATERIALS[k]), min_size=1, max_size=6))
    rng = np.random.default_rng(seed)
    hits = random_hits(rng, 300)
    ids = rng.integers(len(materials), size=300)
    entries = MaterialTable(materials).specular_rays(ids, hits)
    for i in range(300):
        m, hit, ray_in = scalar_hit(materials, ids, hits, i)
        rays = m.specular_rays(ray_in, hit)
        for k, (direction, weight, mask) in enumerate(entries):
            assert mask[i] == (k < len(rays))
            if k < len(rays):
                assert_agrees(
                    direction[i], tuple(rays[k][0].direction), f"ray {k} direction", LIBM_REL
                )
                # the refracted ray: albedo (1 - R)
                scale = tuple(m.albedo.value(hit)) if k == 1 else None
                assert_agrees(weight[i], tuple(rays[k][1]), f"ray {k} weight", LIBM_REL, scale)
            else:
                assert not direction[i].any() and not weight[i].any()
        assert len(rays) <= len(entries)


# --- sampling -----------------------------------------------------------------------------


@pytest.mark.parametrize("kind", NON_SPECULAR)
@settings(max_examples=10)
@given(data=st.data(), seed=seeds)
def test_scattering_equals_scalar_from_the_same_numbers(kind, data, seed):
    table, ids, hits, rng = random_table(data, kind, seed, 150)
    with pytest.MonkeyPatch.context() as monkeypatch:
        use_scalar_local_samplers(monkeypatch)
        check_scattering_equals_scalar(table, ids, hits, rng)


@pytest.mark.parametrize("kind", NON_SPECULAR)
@settings(max_examples=8)
@given(data=st.data(), seed=seeds)
def test_sample_weight_and_pdf_match_brdf_and_pdf(kind, data, seed):
    table, ids, hits, rng = random_table(data, kind, seed, 2000)
    check_samples_match_brdf_and_pdf(table, ids, hits, table.scattering(ids, hits, rng))


@pytest.mark.parametrize(
    ("material", "theta"),
    SAMPLING_CASES,
    ids=["lambertian", "oren_nayar", "phong", "blinn_phong", "ggx", "beckmann", "ward", "glass"],
)
@pytest.mark.slow
def test_sampler_agrees_with_scalar_and_follows_pdf(material, theta):
    phi = 30.0  # off the tangent axis: anisotropy and the frame's orientation count
    batched = compare_with_scalar_sampler(material, theta, phi)
    result = chi2_test(material, theta, phi_deg=phi, samples=head(batched, 30_000))
    assert result.passed(CHI2_ALPHA), result.summary()


# --- which kernel -------------------------------------------------------------------------


class Glow(Material):
    """A material of its own class: no kernel."""

    is_emitter = True


def test_every_scene_material_and_the_glowing_lambertian_have_a_registered_kernel():
    from rtpy.testing.analytic_scenes import GlowingLambertian

    classes = [*SCENE_MATERIALS.values(), GlowingLambertian]
    names = {class_name(cls) for cls in classes}
    assert names == set(KERNELS), "every class has a kernel, every kernel a class"
    assert len(names) == len(classes)
    glowing = GlowingLambertian(Color(0.5, 0.5, 0.5), Color(1.0, 1.0, 1.0))
    assert kernel_class(glowing) is KERNELS[class_name(GlowingLambertian)]


class Subclassed(Lambertian):
    """A subclass may override anything: its own methods compute it."""


def test_a_subclass_of_a_registered_class_uses_the_scalar_fallback():
    assert kernel_class(Subclassed()) is ScalarFallback
    assert kernel_class(Lambertian()) is KERNELS[class_name(Lambertian)]


def test_unknown_classes_use_the_scalar_fallback():
    assert kernel_class(Grey()) is ScalarFallback
    assert kernel_class(Glow()) is ScalarFallback
    assert kernel_class(Lambertian()) is not ScalarFallback
    broken = Lambertian()
    broken.albedo = Color(0.1, 0.2, 0.3)  # not a texture: only the scalar code knows
    assert kernel_class(broken) is ScalarFallback


# --- the number of kernel calls does not grow with the number of materials ---------------------


def cover_like(n: int) -> list[Material]:
    """n materials of five classes, each with its own parameters (like the RTIOW cover)."""
    rng = np.random.default_rng(n)
    out: list[Material] = []
    for i in range(n):
        c, x = Color(*rng.random(3)), float(rng.random())
        kind = i % 5
        if kind == 0:
            out.append(Lambertian(c))
        elif kind == 1:
            out.append(Metal(c, x))
        elif kind == 2:
            out.append(Dielectric(1.0 + x))
        elif kind == 3:
            out.append(Phong(c, 0.5, 0.5, 100.0 * x))
        else:
            out.append(CookTorrance(c, 0.5, 0.5, 0.01 + 0.99 * x))
    return out


METHODS = ("flat_color", "emitting", "BRDF", "pdf", "BRDF_and_pdf", "scattering", "specular_rays")


def run_all(table: MaterialTable, ids, hits, wi) -> None:
    table.flat_color(ids, hits)
    table.emitting(ids, hits)
    table.BRDF(ids, hits, wi)
    table.pdf(ids, hits, wi)
    table.BRDF_and_pdf(ids, hits, wi)
    table.scattering(ids, hits, np.random.default_rng(0))
    table.specular_rays(ids, hits)


def test_kernel_calls_are_bounded_by_the_material_classes():
    table = MaterialTable(cover_like(500))
    assert len(table.kernels) == 5
    calls = dict.fromkeys(METHODS, 0)
    for kernel in table.kernels:
        for name in METHODS:
            method = getattr(kernel, name)

            def spy(*args, _method=method, _name=name):
                calls[_name] += 1
                return _method(*args)

            setattr(kernel, name, spy)
    rng = np.random.default_rng(0)
    hits = random_hits(rng, 5000)
    ids = rng.integers(500, size=5000)
    run_all(table, ids, hits, random_wi(rng, hits))
    # one call per class present that has something to compute
    expected = {"flat_color": 5, "emitting": 0, "BRDF": 3, "pdf": 3, "scattering": 5}
    assert calls == {**expected, "BRDF_and_pdf": 3, "specular_rays": 2}

    calls.update(dict.fromkeys(METHODS, 0))
    lambertian = np.flatnonzero([type(m) is Lambertian for m in table.materials])
    run_all(table, rng.choice(lambertian, 5000), hits, random_wi(rng, hits))
    expected = {"flat_color": 1, "emitting": 0, "BRDF": 1, "pdf": 1, "scattering": 1}
    assert calls == {**expected, "BRDF_and_pdf": 1, "specular_rays": 0}


def count_calls(fn) -> int:
    """Python and C function calls (numpy's included) made while fn() runs, after a
    first run (which may fill caches) and with the garbage collector off (whose
    finalizers would count as calls of whatever runs when it does)."""
    count = 0

    def profile(frame, event, arg):
        nonlocal count
        if event in ("call", "c_call"):
            count += 1

    fn()
    gc.collect()
    gc.disable()
    sys.setprofile(profile)
    try:
        fn()
    finally:
        sys.setprofile(None)
        gc.enable()
    return count


def test_numpy_calls_do_not_grow_with_the_number_of_materials():
    rng = np.random.default_rng(3)
    hits = random_hits(rng, 2000)
    wi = random_wi(rng, hits)
    kind = rng.integers(5, size=2000)
    few, many = MaterialTable(cover_like(5)), MaterialTable(cover_like(500))
    ids_many = kind + 5 * rng.integers(100, size=2000)  # the same class per hit
    n_few = count_calls(lambda: run_all(few, kind, hits, wi))
    n_many = count_calls(lambda: run_all(many, ids_many, hits, wi))
    assert n_many == n_few
