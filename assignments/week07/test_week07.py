# ruff: noqa: E501  (the assertion messages are prose for students)
"""Week 07 graders: sphere and quad (u, v), checker and image textures, metal fuzz.
Run them with `python -m rtpy grade 07`.

Each test is a verdict: it asks the student's code for numbers through `probe`
(the probes are in probes.py beside this file) and decides here, in the judge. Each
names the method it checks and says what is wrong when it fails.
"""

import math
from pathlib import Path

import numpy as np

from rtpy.grading import assert_image_matches, points, scene_uses

HERE = Path(__file__).parent


@points(2, task="07.1")
def test_sphere_uv(probe):
    """Sphere.surface_uv: u = phi / 2 pi from -x around +y, v = theta / pi from -y"""
    rng = np.random.default_rng(7)
    c, r = np.array([0.3, -0.2, 0.5]), 1.7
    angles, cases = [], []
    for _ in range(50):
        theta, phi = rng.uniform(0.01, math.pi - 0.01), rng.uniform(0.01, 2 * math.pi - 0.01)
        # theta from -y, phi from -x toward +z... : point = (-cos phi sin theta, -cos theta, sin phi sin theta)
        p = c + r * np.array(
            [-math.cos(phi) * math.sin(theta), -math.cos(theta), math.sin(phi) * math.sin(theta)]
        )
        angles.append((theta, phi, p))
        cases.append({"center": c, "radius": r, "point": p, "normal": (p - c) / r})
    got = probe.week07_sphere_surface_uv(cases=cases)
    for (theta, phi, p), (u, vv) in zip(angles, got, strict=True):
        assert abs(u - phi / (2 * math.pi)) < 1e-9 and abs(vv - theta / math.pi) < 1e-9, (
            f"Sphere.surface_uv (rtpy/sphere.py) at {p.round(3)}: (u, v) = ({u:.4f}, {vv:.4f}), expected "
            f"({phi / (2 * math.pi):.4f}, {theta / math.pi:.4f}): u = phi / (2 pi) with phi measured "
            "from -x around +y (toward +z first), v = theta / pi with theta from -y"
        )


@points(2, task="07.1")
def test_quad_uv(probe):
    """Quad.surface_uv: p = q + u * U + v * V"""
    rng = np.random.default_rng(77)
    coords, cases = [], []
    for _ in range(50):
        q, uu, vv = rng.uniform(-1, 1, 3), rng.normal(size=3), rng.normal(size=3)
        a, b = rng.uniform(0, 1, 2)
        coords.append((a, b))
        cases.append({"q": q, "u": uu, "v": vv, "point": q + a * uu + b * vv})
    got = probe.week07_quad_surface_uv(cases=cases)
    for (a, b), uv in zip(coords, got, strict=True):
        assert abs(uv[0] - a) < 1e-9 and abs(uv[1] - b) < 1e-9, (
            f"Quad.surface_uv (rtpy/quad.py): the point q + {a:.3f} u + {b:.3f} v got (u, v) = "
            f"({uv[0]:.4f}, {uv[1]:.4f})"
        )


@points(2, task="07.2")
def test_checker_texture(probe):
    """CheckerTexture.value: 3-D cells of edge `scale`"""
    rng = np.random.default_rng(8)
    even, odd = [0.9, 0.9, 0.9], [0.1, 0.2, 0.3]
    cases = []
    for _ in range(200):
        scale = rng.uniform(0.2, 2)
        p = rng.uniform(-5, 5, 3)
        cases.append({"scale": scale, "even": even, "odd": odd, "point": p})
    got = probe.week07_checker_value(cases=cases)
    for case, value in zip(cases, got, strict=True):
        p, scale = case["point"], case["scale"]
        cell = int(sum(math.floor(x / scale) for x in p))
        expected = even if cell % 2 == 0 else odd
        assert list(value) == expected, (
            f"CheckerTexture.value (rtpy/texture.py) at {p.round(3)}, scale {scale:.3f}: got {value.round(4)}, "
            f"expected the {'even' if cell % 2 == 0 else 'odd'} colour (floor(x/s) + floor(y/s) + "
            "floor(z/s) even or odd; floor, not int, so negative coordinates work)"
        )


@points(2, task="07.2")
def test_image_texture(probe):
    """ImageTexture.value: nearest texel, u from the left, v from the bottom row"""
    h, w = 5, 7
    pixels = np.arange(h * w * 3, dtype=float).reshape(h, w, 3) / (h * w * 3)
    rng = np.random.default_rng(9)
    uv = [rng.uniform(0, 1, 2) for _ in range(100)]
    got = probe.week07_image_texture_value(pixels=pixels, uv=uv)
    for (u, vv), value in zip(uv, got, strict=True):
        i, j = min(int(u * w), w - 1), min(int((1 - vv) * h), h - 1)
        assert np.allclose(value, pixels[j, i]), (
            f"ImageTexture.value (rtpy/texture.py) at (u, v) = ({u:.3f}, {vv:.3f}) gave {value.round(4)}, "
            f"expected the texel in column {i}, row {j} (row 0 is the image's top, v = 0 its bottom)"
        )


@points(3, task="07.3")
def test_metal_fuzz(probe):
    """Metal.scattering: reflection + fuzz * random unit vector, absorbed below the surface"""
    n = np.array([0.0, 0.0, 1.0])
    t = math.radians(75)  # grazing: fuzz can push directions below the surface
    origin, direction = [math.sin(t), 0, math.cos(t)], [-math.sin(t), 0, -math.cos(t)]
    r = np.array([-math.sin(t), 0, math.cos(t)])
    albedo = [0.8, 0.6, 0.4]
    where = "Metal.scattering (rtpy/materials/metal.py)"
    n_samples, fuzzes = 3000, (0.1, 0.5)
    cases = [{"albedo": albedo, "fuzz": 0.0, "origin": origin, "direction": direction,
              "normal": n, "count": 1, "generator": None}]  # fmt: skip
    for fuzz in fuzzes:
        cases.append(dict(cases[0], fuzz=fuzz, count=n_samples, generator=[7, int(fuzz * 10)]))
    mirror, *fuzzed = probe.week07_metal_scatter(cases=cases)
    assert mirror[0, 0] == 1.0 and np.allclose(mirror[0, 1:4], r, atol=1e-12), (
        f"{where}: fuzz 0 must be a perfect mirror"
    )
    for fuzz, rows in zip(fuzzes, fuzzed, strict=True):
        absorbed = int((rows[:, 0] == 0.0).sum())
        samples = rows[rows[:, 0] == 1.0]
        d = samples[:, 1:4]
        assert np.all(np.abs(np.linalg.norm(d, axis=1) - 1) < 1e-9), (
            f"{where}: the direction must be a unit vector"
        )
        assert np.all(d @ n > 0), (
            f"{where}: a fuzzed direction below the surface must be absorbed (None)"
        )
        assert np.allclose(samples[:, 4:7], albedo), f"{where}: the weight is the albedo"
        angles = np.degrees(np.arccos(np.minimum(1.0, d @ r)))
        # The fuzz point is uniform on a sphere of radius fuzz around the mirror
        # direction; directions below the surface are absorbed. Compare with that
        # distribution: the absorbed fraction, the largest and the mean angle.
        rng = np.random.default_rng(1)
        ref = rng.normal(size=(200_000, 3))
        ref = r + fuzz * ref / np.linalg.norm(ref, axis=1)[:, None]
        above = ref @ n > 0
        p_absorbed = 1 - above.mean()
        z = (absorbed / n_samples - p_absorbed) / math.sqrt(
            max(p_absorbed * (1 - p_absorbed), 1e-4) / n_samples
        )
        assert abs(z) < 4.5, (
            f"{where} with fuzz {fuzz} at 75 degrees: {absorbed} of {n_samples} samples absorbed, expected "
            f"about {p_absorbed * n_samples:.0f} (directions pushed below the surface return None)"
        )
        assert len(angles) > 0, f"{where} with fuzz {fuzz}: every sample was absorbed (None)"
        ref = ref[above]
        limit = math.degrees(math.asin(fuzz)) + 1e-6
        assert angles.max() <= limit, (
            f"{where} with fuzz {fuzz}: a direction {angles.max():.1f} degrees from the mirror "
            f"direction; reflect + fuzz * (a unit vector) stays within asin(fuzz) = {limit:.1f} degrees"
        )
        ref_angles = np.degrees(np.arccos(np.clip(ref @ r / np.linalg.norm(ref, axis=1), -1, 1)))
        z = (angles.mean() - ref_angles.mean()) / (ref_angles.std() / math.sqrt(len(angles)))
        assert abs(z) < 4.5, (
            f"{where} with fuzz {fuzz}: mean angle to the mirror direction {angles.mean():.2f} degrees, "
            f"expected {ref_angles.mean():.2f} for a uniform random unit vector times fuzz (z = {z:.1f})"
        )


# The center integrator is deterministic at spp 1 (each pixel's centre), so the
# seed fixes the image.
REFERENCE = {"name": "center_textures"}
RENDER = {"integrator": "center", "spp": 1}
TEXTURE = np.random.default_rng(3).uniform(0, 1, (8, 16, 3))  # the image texture's pixels


def render_textures(probe):
    return probe.render(
        scene="week07_textures", seeds=[0], settings=RENDER, params={"pixels": TEXTURE}
    )[0]


def make_reference_image(probe):
    return render_textures(probe)


@points(2, task="07.2")
@scene_uses("07.1")
def test_texture_render_matches_reference(probe):
    """center render of checker and image textures matches the reference"""
    image = render_textures(probe)
    reference = np.load(HERE / "reference" / f"{REFERENCE['name']}.npy", allow_pickle=False)
    assert_image_matches(
        image, reference, "center render with textures",
        "check the (u, v) of spheres and quads and the texture lookups", rtol=1e-9, atol=1e-12,
    )  # fmt: skip
