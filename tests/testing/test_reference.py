"""References: closed forms for the analytic scenes; rendered references cached on
disk with their settings and noise, refused when the scene file changes."""

from __future__ import annotations

import json

import numpy as np
import pytest

from rtpy.testing import reference as reference_module
from rtpy.testing.analytic_scenes import analytic_scene
from rtpy.testing.reference import (
    StaleReference,
    analytic_reference,
    file_sha256,
    get_reference,
    load_reference,
    reference_dir,
    render_reference,
)


def one_ball(camera: str, render: str, albedo: str, center: str, radius: float) -> str:
    """A square scene file with [camera] and [render] lines and one Lambertian ball."""
    return (
        f"[camera]\n{camera}aspect_ratio = 1.0\n\n[render]\n{render}\n"
        f'[materials.ball]\ntype = "lambertian"\nalbedo = {albedo}\n\n'
        f'[[objects]]\ntype = "sphere"\ncenter = {center}\nradius = {radius}\nmaterial = "ball"\n'
    )


# A furnace as a scene file: a Lambertian sphere in a white environment shows
# exactly its albedo, at every sample, so a rendered reference must too.
FURNACE_TOML = one_ball(
    "look_at = [0, 0, -3]\nvfov = 50\n",
    "background = [1, 1, 1]\nmax_depth = 4\n",
    "[0.7, 0.35, 0.25]",
    "[0, 0, -3]",
    1,
)
# A noisy one: a ball under the sky.
SKY_TOML = one_ball("", "sky = true\nmax_depth = 3\n", "[0.6, 0.6, 0.6]", "[0, -0.2, -1]", 0.6)


PLANE_TOML = """\
[camera]
look_from = [0, 3, 2]
look_at = [0, 0, -1]
vfov = 60
aspect_ratio = 1.0

[render]
sky = true
max_depth = 3

[materials.ground]
type = "lambertian"
albedo = [0.6, 0.6, 0.6]

[[objects]]
type = "quad"
q = [-50, 0, -50]
u = [0, 0, 100]
v = [100, 0, 0]
material = "ground"
"""


def no_render(*args, **kwargs):
    raise AssertionError("the cached reference should have been used")


def quiet(_msg):
    pass


def test_analytic_reference_is_exact_with_no_noise():
    a = analytic_scene("plane_sky_band")
    ref = analytic_reference(a, a.camera, 4)
    assert ref.exact and ref.noise_floor == 0.0 and ref.mask.all()
    np.testing.assert_array_equal(ref.image, a.exact(a.camera, 4)[0])


def test_rendered_reference_of_a_furnace_is_its_albedo(tmp_path):
    path = tmp_path / "furnace.toml"
    path.write_text(FURNACE_TOML)
    ref = get_reference(path, 16, 4, spp=8, cache=tmp_path / "cache", log=quiet)
    assert not ref.exact
    centre = ref.image[8, 8]
    np.testing.assert_allclose(centre, [0.7, 0.35, 0.25], rtol=1e-12)
    np.testing.assert_allclose(ref.image[0, 0], 1.0, rtol=1e-12)
    assert ref.variance[8, 8].max() < 1e-24  # every sample exact: no spread


def test_cached_reference_is_reused_with_its_settings(tmp_path, monkeypatch):
    path = tmp_path / "sky.toml"
    path.write_text(SKY_TOML)
    cache = tmp_path / "cache"
    first = get_reference(path, 12, 3, spp=16, cache=cache, log=quiet)
    meta = json.loads((cache / "sky-w12-d3.json").read_text())
    assert meta["scene_sha256"] == file_sha256(path)
    assert meta["spp"] == 16 and meta["max_depth"] == 3 and meta["width"] == 12
    assert meta["integrator"] == "path" and meta["mis"] and meta["backend"] == "numpy"
    assert first.noise_floor > 0
    monkeypatch.setattr(reference_module, "render_reference", no_render)
    again = get_reference(path, 12, 3, spp=16, cache=cache, log=quiet)
    np.testing.assert_array_equal(again.image, first.image)
    np.testing.assert_array_equal(again.variance, first.variance)
    # fewer spp than cached is fine; more is not
    assert load_reference(path, 12, 3, 8, cache) is not None
    with pytest.raises(StaleReference, match="16 spp"):
        load_reference(path, 12, 3, 64, cache)
    assert load_reference(path, 13, 3, 8, cache) is None  # another width: not cached


def test_changed_scene_file_is_refused_and_the_reference_made_again(tmp_path):
    path = tmp_path / "sky.toml"
    path.write_text(SKY_TOML)
    cache = tmp_path / "cache"
    old = get_reference(path, 12, 3, spp=8, cache=cache, log=quiet)
    path.write_text(SKY_TOML.replace("[0.6, 0.6, 0.6]", "[0.3, 0.6, 0.6]"))
    with pytest.raises(StaleReference, match="different version"):
        load_reference(path, 12, 3, 8, cache)
    messages = []
    new = get_reference(path, 12, 3, spp=8, cache=cache, log=messages.append)
    assert any("refusing" in m for m in messages)
    assert json.loads((cache / "sky-w12-d3.json").read_text())["scene_sha256"] == file_sha256(path)
    ball = new.image[6, 6]
    assert ball[0] < 0.75 * old.image[6, 6, 0]  # the red albedo halved
    assert load_reference(path, 12, 3, 8, cache) is not None


def test_unreadable_cache_entry_is_refused(tmp_path):
    path = tmp_path / "sky.toml"
    path.write_text(SKY_TOML)
    cache = tmp_path / "cache"
    cache.mkdir()
    (cache / "sky-w12-d3.npz").write_bytes(b"not an npz")
    (cache / "sky-w12-d3.json").write_text("{}")
    with pytest.raises(StaleReference, match="unreadable"):
        load_reference(path, 12, 3, 8, cache)


def test_reference_noise_estimate_matches_the_spread_of_two_references(tmp_path):
    """Two references made with different seeds differ by d with E[d^2] = v1 + v2
    per value. On a plane under the sky (every pixel about equally noisy; the
    three channels move together, so they count as one) of 24 x 24 pixels, the
    ratio mean(d^2) / mean(v1 + v2) has a relative standard error of about
    sqrt(2/576) = 0.059 in the numerator and sqrt(2/(3*576)) = 0.034 in the
    denominator (4 renders give each variance 3 degrees of freedom): 0.068 in
    all, so |ratio - 1| < 0.3 is a 4.4-sigma bound (measured over 12 seed pairs:
    standard deviation 0.064). A variance not divided by the number of renders
    would give a ratio of 4."""
    path = tmp_path / "plane.toml"
    path.write_text(PLANE_TOML)
    a, va, _ = render_reference(path, 24, 3, 32, seed=10)
    b, vb, _ = render_reference(path, 24, 3, 32, seed=20)
    ratio = ((a - b) ** 2).mean() / (va + vb).mean()
    assert abs(ratio - 1) < 0.3, ratio


def test_reference_dir_follows_the_environment(monkeypatch, tmp_path):
    monkeypatch.setenv("RTPY_CACHE", str(tmp_path / "c"))
    assert reference_dir() == tmp_path / "c" / "references"
    monkeypatch.delenv("RTPY_CACHE")
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "x"))
    assert reference_dir() == tmp_path / "x" / "rtpy" / "references"


def test_a_failed_cache_write_leaves_no_file_and_names_the_path(tmp_path, monkeypatch):
    """Writing the cache goes through rtpy.io.image.atomic_write: a disk that fills up
    half-way through gives one WriteError naming the file, and no partial or temporary
    file stays in the cache (a later run would otherwise read half an image)."""
    import errno

    from rtpy.io.image import WriteError

    scene = tmp_path / "furnace.toml"
    scene.write_text(FURNACE_TOML)
    image = np.ones((2, 2, 3))
    monkeypatch.setattr(
        reference_module, "render_reference", lambda *a: (image, 0.0 * image, {"source": "x"})
    )

    def half_then_full(f, **arrays):
        f.write(b"PK\x03\x04")  # the start of a zip archive, as np.savez begins
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(reference_module.np, "savez", half_then_full)
    cache = tmp_path / "cache"
    with pytest.raises(WriteError, match=r"cannot write .*furnace.*\.npz.: No space left"):
        get_reference(scene, 2, 4, spp=4, cache=cache, log=lambda _: None)
    assert list(cache.iterdir()) == []
