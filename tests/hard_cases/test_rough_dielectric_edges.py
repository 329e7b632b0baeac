"""Hard cases for rough glass (rtpy.materials.RoughDielectric), rendered or sampled:

- roughness -> 0 gives the smooth `dielectric` image (with the exact Fresnel
  reflectance in both), by the block z-test;
- ior -> 1 gives an invisible surface;
- grazing incidence from both sides gives finite, consistent samples;
- total internal reflection from inside: nothing passes beyond the critical angle;
- light leaving a glass block: an emitter inside glass seen from outside has the
  radiance Le T / eta^2 (T the surface's transmittance), and a camera inside glass
  sees the outside eta^2 times brighter, in both backends and with or without light
  sampling (light sampling through the surface, MIS and the 1/eta^2 all count);
- a small light behind rough glass: one bounce equals the integral of the BSDF over
  the emitter, which light sampling reaches through the surface (|cos|) and MIS
  shares with the BSDF's samples.

Images are compared block by block (rtpy.testing.statistics.block_z_test) against the
noise of several renders with different seeds; the closed forms by a z-test of the
pixels' mean against the noise of the pixels.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

import rtpy
from rtpy.camera import Camera
from rtpy.hit_info import HitInfo
from rtpy.integrators import direct_lighting
from rtpy.materials import Dielectric, DiffuseLight, RoughDielectric
from rtpy.numpy_backend.materials import dielectric as numpy_dielectric
from rtpy.numpy_backend.materials import rough_dielectric as numpy_rough
from rtpy.quad import Quad
from rtpy.ray import Ray
from rtpy.scene import Scene
from rtpy.sphere import Sphere
from rtpy.testing import (
    check_non_negative_finite,
    check_weights,
    directional_albedo,
    draw_samples,
    normal_quantile,
)
from rtpy.testing.statistics import block_z_test
from rtpy.vec3 import Color, Vec3

from ..cores import module_outcomes, outcome
from ..materials.test_rough_dielectric import InvertedScaling
from ..tiers import slow_except

ALPHA = 1e-3  # chance that a correct renderer fails a comparison
Z = normal_quantile(ALPHA)
WHITE = Color(1.0, 1.0, 1.0)
SEEDS = (1, 2, 3, 4)


def render(scene: Scene, camera: Camera, backend: str = "numpy", **settings) -> np.ndarray:
    return rtpy.render(scene, camera=camera, backend=backend, **settings).linear


def renders(scene, camera, spp, **settings) -> np.ndarray:
    """(len(SEEDS), H, W, 3): independent numpy renders."""
    return np.stack([render(scene, camera, spp=spp, seed=s, **settings) for s in SEEDS])


def same_expectation(a: np.ndarray, b: np.ndarray):
    """block_z_test of two stacks of renders, each pixel's variance measured from the
    spread of its renders."""
    n = len(a)
    return block_z_test(
        a.mean(axis=0), a.var(axis=0, ddof=1) / n, b.mean(axis=0), b.var(axis=0, ddof=1) / n, ALPHA
    )


# --- roughness -> 0 ------------------------------------------------------------------------


def box(corner, size, material) -> list[Quad]:
    """The six faces of the box [corner, corner + size], u x v pointing out."""
    x, y, z = corner
    sx, sy, sz = size
    dx, dy, dz = Vec3(sx, 0, 0), Vec3(0, sy, 0), Vec3(0, 0, sz)
    return [
        Quad(Vec3(x, y, z + sz), dx, dy, material),  # front, +z
        Quad(Vec3(x + sx, y, z), -dx, dy, material),  # back, -z
        Quad(Vec3(x + sx, y, z + sz), -dz, dy, material),  # +x
        Quad(Vec3(x, y, z), dz, dy, material),  # -x
        Quad(Vec3(x, y + sy, z + sz), dx, -dz, material),  # top, +y
        Quad(Vec3(x, y, z), dx, dz, material),  # bottom, -y
    ]


BRIGHT, DIM = DiffuseLight(Color(1.0, 0.9, 0.7)), DiffuseLight(Color(0.1, 0.15, 0.4))


def glowing_checker(z: float, cells: int = 8, size: float = 0.5) -> list[Quad]:
    """A backdrop of cells x cells emitting squares facing +z, bright and dim in turn:
    what the glass shows needs no lighting, so no caustics add noise."""
    start = -0.5 * cells * size
    return [
        Quad(
            Vec3(start + i * size, start + j * size, z),
            Vec3(size, 0, 0),
            Vec3(0, size, 0),
            BRIGHT if (i + j) % 2 == 0 else DIM,
        )
        for i in range(cells)
        for j in range(cells)
    ]


def glass_ball_scene(material) -> tuple[Scene, Camera]:
    """A glass ball before a glowing checker, in a uniform grey environment."""
    objects = [Sphere(Vec3(0, 0, 0), 0.5, material), *glowing_checker(-1.5)]
    camera = Camera(Vec3(0, 0, 3), Vec3(0, 0, 0), vfov=26, aspect_ratio=1.5, width=36)
    return Scene(objects, background=Color(0.3, 0.3, 0.3)), camera


FRESNEL = numpy_rough.fresnel_dielectric


def exact_schlick(cosine, ior_ratio):
    """Dielectric's reflectance with the exact Fresnel formula for Schlick's."""
    return FRESNEL(cosine, 1.0 / ior_ratio)


def smooth_and_rough(monkeypatch, spp=32):
    monkeypatch.setattr(numpy_dielectric, "schlick", exact_schlick)
    smooth = renders(*glass_ball_scene(Dielectric(1.5)), spp, max_depth=8)
    rough = renders(*glass_ball_scene(RoughDielectric(1.5, 1e-4)), spp, max_depth=8)
    return smooth, rough


def test_roughness_to_zero_gives_the_smooth_dielectric_image(monkeypatch):
    """The smallest roughness (computed as alpha = 1e-4) against smooth glass: the
    same picture, in refraction and reflection. The radiance scaling of rough glass
    (1 / eta^2 in, eta^2 out) cancels along every path through the ball."""
    smooth, rough = smooth_and_rough(monkeypatch)
    test = same_expectation(rough, smooth)
    assert test.passed, "rough glass: " + test.worst("smooth glass")


@pytest.mark.slow
def test_the_smooth_limit_comparison_sees_fresnel_on_the_wrong_side(monkeypatch):
    # eta = n_viewer / n_other instead of n_other / n_viewer
    monkeypatch.setattr(numpy_rough, "fresnel_dielectric", exact_schlick)
    smooth, rough = smooth_and_rough(monkeypatch)
    assert not same_expectation(rough, smooth).passed


# --- ior -> 1 ---------------------------------------------------------------------------------


def pane_scene(ior: float | None) -> tuple[Scene, Camera]:
    """A 0.1 thick pane of anti-glare glass before a glowing checker; ior None leaves
    the pane out."""
    objects = glowing_checker(-1.0, size=0.3)
    if ior is not None:
        pane = RoughDielectric(ior, 0.023, "beckmann")
        objects += box((-0.6, -0.6, -0.05), (1.2, 1.2, 0.1), pane)
    camera = Camera(Vec3(0, 0, 3), Vec3(0, 0, 0), vfov=22, aspect_ratio=1.0, width=24)
    return Scene(objects), camera


@pytest.mark.parametrize("ior", slow_except([1.0, 1.0 + 1e-4], 1.0))
def test_ior_to_one_makes_the_surface_invisible(heavy, request, ior):
    """At ior 1 nothing reflects (F = 0) and refraction goes straight on through
    every facet; with the small roughness the microfacets' masking loses nothing
    the renders can see."""
    test = outcome(heavy, request)
    assert test.passed, f"pane of ior {ior}: " + test.worst("no pane")


def pane_or_not(ior: float):
    """same_expectation of the renders with a pane of ior `ior` and without a pane."""
    return same_expectation(renders(*pane_scene(ior), 32), renders(*pane_scene(None), 32))


@pytest.mark.slow
def test_the_invisibility_comparison_sees_real_glass():
    test = same_expectation(renders(*pane_scene(1.5), 32), renders(*pane_scene(None), 32))
    assert not test.passed


def test_ior_to_one_samples_go_straight_on():
    """Refraction through a facet tilted by t from the viewer bends the light by about
    (ior - 1) tan(t): the same facets (the same seed) bend it ten times more at ior
    1 + 1e-5 than at ior 1, computed as 1 + 1e-6. Nothing reflects."""
    straight = -np.array([math.sin(math.radians(30.0)), 0.0, math.cos(math.radians(30.0))])
    bends = []
    for ior in (1.0, 1.0 + 1e-5):
        s = draw_samples(RoughDielectric(ior, 0.394, "ggx"), 30.0, 2000, seed=2)
        assert not (s.scattered & ~s.transmitted).any()  # nothing reflects
        bends.append(np.linalg.norm(s.directions - straight, axis=1))
    assert np.nanmedian(bends[0]) < 5e-6
    assert np.nanmedian(bends[1] / bends[0]) == pytest.approx(10.0, rel=1e-3)


# --- grazing incidence --------------------------------------------------------------------

GLASSES = [
    RoughDielectric(1.5, 0.023, "beckmann"),
    RoughDielectric(1.5, 0.394, "ggx"),
    RoughDielectric(1.5, 0.553, "ggx"),
]


@pytest.mark.parametrize(
    "glass, inside", slow_except([(g, s) for g in range(3) for s in (0, 1)], (1, 1), (0, 0))
)
def test_grazing_incidence_from_both_sides(glass, inside):
    m, inside = GLASSES[glass], bool(inside)
    assert check_non_negative_finite(m, inside=inside, n=200)
    for theta in (89.9, 89.999, 90.0 - 1e-9):
        assert check_weights(m, theta, n=300, inside=inside)


# --- total internal reflection --------------------------------------------------------


def test_total_internal_reflection_from_inside(heavy, request):
    """Beyond the critical angle (41.8 degrees for ior 1.5) smooth-ish glass seen from
    inside passes nothing: every sample reflects, with F = 1 and a weight of about 1;
    just inside the critical angle light passes. Schlick's approximation would let
    light through beyond it (it knows no critical angle)."""
    beyond, a, within = outcome(heavy, request)
    for theta, s in beyond.items():
        assert s.scattered.any() and not s.transmitted.any()
        if theta < 85.0:  # at 85 degrees masking blocks some of the reflection
            assert s.scattered.all()
            assert np.mean(s.weights[:, 0]) == pytest.approx(1.0, abs=2e-3)
    assert a.transmitted == (0.0, 0.0, 0.0) and a.lost[0] == pytest.approx(0.0, abs=1e-3)
    assert within.transmitted.mean() > 0.3


def samples_from_inside():
    """Anti-glare glass from inside: ({theta: 10,000 samples} beyond the critical angle,
    the directional albedo at 60 degrees, 2000 samples at 40 degrees)."""
    m = GLASSES[0]
    beyond = {theta: draw_samples(m, theta, 10_000, inside=True) for theta in (50.0, 60.0, 85.0)}
    a = directional_albedo(m, 60.0, n_samples=2000, inside=True)
    return beyond, a, draw_samples(m, 40.0, 2000, inside=True)


# --- light leaving a glass block, and a camera inside glass -----------------------------------


def block_with_light_inside(material, le: float) -> tuple[Scene, Camera]:
    """A glass block whose front face the camera sees head on (within 1 degree), with an
    emitter facing the camera just behind that face, filling every direction that
    light refracted into the block can take."""
    objects = box(Vec3(-2, -2, -1.0), (4.0, 4.0, 1.0), material)
    objects.append(
        Quad(
            Vec3(-1.9, -1.9, -0.02),
            Vec3(3.8, 0, 0),
            Vec3(0, 3.8, 0),
            DiffuseLight(Color(le, le, le)),
        )
    )
    camera = Camera(Vec3(0, 0, 10), Vec3(0, 0, 0), vfov=2.0, aspect_ratio=1.0, width=8)
    return Scene(objects), camera


def check_closed_form(image: np.ndarray, expected: float, allowance: float) -> None:
    """The pixels' mean equals `expected` (the same in every pixel) up to the noise of
    the pixels and the allowance for the closed form's own error."""
    values = image[..., 0].ravel()
    se = values.std(ddof=1) / math.sqrt(values.size)
    assert abs(values.mean() - expected) <= Z * se + allowance, (values.mean(), expected, se)


@pytest.mark.parametrize(
    "backend, nee, glass",
    slow_except(
        [(b, n, g) for b in ("numpy", "scalar") for n in (True, False) for g in (0, 2)],
        ("numpy", True, 2),
    ),
)
def test_light_leaving_a_glass_block(heavy, request, backend, nee, glass):
    """Radiance Le inside the glass leaves it as Le * (the surface's transmitted albedo
    from outside), which for smooth glass at normal incidence is Le (1 - F0) / eta^2:
    the camera sees the emitter 2.25 times dimmer than in air, less what the surface
    reflects. With light sampling, the emitter behind the surface is sampled through
    it and MIS shares it with the samples of the BSDF."""
    image, a = outcome(heavy, request)
    check_closed_form(image, 3.0 * a.transmitted[0], 3.0 * 10 * a.quadrature_error + 1e-4)
    if glass == 0:  # nearly smooth: (1 - F0) / eta^2, less a hair of masking
        assert a.transmitted[0] == pytest.approx(0.96 / 2.25, rel=1e-3)


def block_image_and_albedo(backend: str, nee: bool, glass: int):
    """The render of the block with the light inside, and the glass's directional albedo
    at normal incidence from outside."""
    m = GLASSES[glass]
    scene, camera = block_with_light_inside(m, 3.0)
    spp = 256 if backend == "numpy" else 32
    image = render(scene, camera, backend, spp=spp, max_depth=4, nee=nee, seed=5)
    return image, directional_albedo(m, 0.0, n_samples=5000)


def test_a_bsdf_for_importance_makes_the_light_in_the_block_too_bright():
    scene, camera = block_with_light_inside(InvertedScaling(1.5, 0.023, "beckmann"), 3.0)
    image = render(scene, camera, "numpy", spp=64, max_depth=4, seed=5)
    assert image[..., 0].mean() == pytest.approx(3.0 * 0.96, rel=0.05)  # not / eta^2


def small_light_behind_glass(material) -> tuple[Scene, Camera, Quad]:
    """A small emitter inside a glass block, 1 behind the face the camera sees head on
    from far away (all camera rays meet the face within 0.01 of its centre): light
    sampling finds it through the surface far better than the BSDF's samples do."""
    light = Quad(Vec3(-0.2, -0.2, -1.0), Vec3(0.4, 0, 0), Vec3(0, 0.4, 0), DiffuseLight(WHITE))
    objects = [*box((-2.0, -2.0, -3.0), (4.0, 4.0, 3.0), material), light]
    camera = Camera(Vec3(0, 0, 20), Vec3(0, 0, 0), vfov=0.05, aspect_ratio=1.0, width=8)
    return Scene(objects), camera, light


def direct_light_through(material, light: Quad) -> float:
    """The radiance the centre of the face sends toward +z after one scattering of the
    light of `light` (radiance 1): the integral over the emitter of BRDF |cos(theta_i)|
    cos(theta_light) / r^2 dA, by Gauss-Legendre quadrature on 8 x 8 cells."""
    x, w = np.polynomial.legendre.leggauss(8)
    nodes = [(c + (xi + 1.0) / 2.0) / 8.0 for c in range(8) for xi in x]
    weights = [wi / 16.0 for _ in range(8) for wi in w]
    hit = HitInfo(Vec3(0, 0, 0), Vec3(0, 0, 1), 1.0, True, material)
    view = Ray(Vec3(0, 0, 1), Vec3(0, 0, -1))
    total = 0.0
    for a, wa in zip(nodes, weights, strict=True):
        for b, wb in zip(nodes, weights, strict=True):
            point = light.q + light.u * a + light.v * b
            r2 = point.length_squared()
            wi = point / math.sqrt(r2)
            f = material.BRDF(view, Ray(Vec3(0, 0, 0), wi), hit).e0
            total += wa * wb * f * abs(wi.e2) * abs(wi.e2) / r2  # cos_i = cos_light here
    return total * light.u.length() * light.v.length()


@pytest.mark.parametrize(
    "backend, nee",
    slow_except([("numpy", True), ("numpy", False), ("scalar", True)], ("numpy", True)),
)
def test_a_light_behind_rough_glass_is_sampled_through_it(backend, nee):
    """Light sampling counts a light behind the surface where the BSDF transmits (with
    |cos|), and MIS shares it with the BSDF's samples: with light sampling, without it,
    both give the integral of the BSDF over the emitter (one bounce: max_depth 2)."""
    m = GLASSES[2]
    scene, camera, light = small_light_behind_glass(m)
    spp = {("numpy", True): 256, ("numpy", False): 4096, ("scalar", True): 64}[backend, nee]
    image = render(scene, camera, backend, spp=spp, max_depth=2, nee=nee, seed=7)
    # 1e-3: the camera's rays meet the face within 0.01 of its centre, where the
    # integral is taken; that moves it by about 1e-4 (the linear terms cancel).
    check_closed_form(image, direct_light_through(m, light), 1e-3 * direct_light_through(m, light))


def test_light_sampling_that_skips_lights_behind_the_surface_is_caught(monkeypatch):
    """Light sampling with max(cos, 0) instead of |cos| never counts the light behind
    the surface, while MIS still gives the BSDF's samples only their share of it."""
    monkeypatch.setattr(direct_lighting, "abs", lambda x: max(x, 0.0), raising=False)
    m = GLASSES[2]
    scene, camera, light = small_light_behind_glass(m)
    image = render(scene, camera, "scalar", spp=64, max_depth=2, seed=7)
    with pytest.raises(AssertionError):
        check_closed_form(image, direct_light_through(m, light), 1e-3)


def inside_a_glass_ball(material) -> tuple[Scene, Camera]:
    """The camera at the centre of a glass ball, in a uniform environment of radiance 1."""
    scene = Scene([Sphere(Vec3(0, 0, 0), 5.0, material)], background=WHITE)
    camera = Camera(Vec3(0, 0, 0), Vec3(0, 0, -1), vfov=60, aspect_ratio=1.0, width=8)
    return scene, camera


@pytest.mark.parametrize("backend", slow_except(["numpy", "scalar"], "numpy"))
def test_a_camera_inside_glass_sees_the_outside_eta_squared_brighter(heavy, request, backend):
    """Every camera ray meets the ball at normal incidence from inside and refracts out
    with weight eta^2 (1 - F0), or reflects (F0) to the other side and tries again:
    L = eta^2 (1 - F0) (1 + F0 + F0^2 + ...) = eta^2, the radiance of an equilibrium in
    a medium of index eta. The masking of anti-glare glass loses less than 1e-4."""
    image, a = outcome(heavy, request)
    lost = a.lost[0]
    assert abs(lost) < 1e-4
    check_closed_form(image, 2.25, 2.25 * (2.0 * abs(lost) + 10.0 * a.quadrature_error) + 1e-4)


def ball_image_and_albedo(backend: str):
    """The render from the centre of the anti-glare glass ball, and the glass's
    directional albedo at normal incidence from inside."""
    m = GLASSES[0]
    scene, camera = inside_a_glass_ball(m)
    spp = 256 if backend == "numpy" else 32
    image = render(scene, camera, backend, spp=spp, max_depth=12, seed=3)
    return image, directional_albedo(m, 0.0, n_samples=2000, inside=True)


# node id -> the renders and samples of each selected test, on every core, the longest
# first.
heavy = module_outcomes(
    {
        "test_light_leaving_a_glass_block": block_image_and_albedo,
        "test_a_camera_inside_glass_sees_the_outside_eta_squared_brighter": (ball_image_and_albedo),
        "test_total_internal_reflection_from_inside": samples_from_inside,
        "test_ior_to_one_makes_the_surface_invisible": pane_or_not,
    }
)


def test_a_camera_inside_glass_sees_the_transport_direction():
    """With the BSDF for importance (n_i^2 for n_o^2) the eta^2 of radiance is lost: the
    camera inside the ball sees the outside as it is, 1, not 2.25."""
    scene, camera = inside_a_glass_ball(InvertedScaling(1.5, 0.023, "beckmann"))
    image = render(scene, camera, "numpy", spp=64, max_depth=12, seed=3)
    assert image[..., 0].mean() == pytest.approx(1.0, abs=0.05)
