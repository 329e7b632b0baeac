"""The batched samplers (rtpy/numpy_backend/sampler.py) give rtpy.sampler's values,
sample for sample; LaneSampler serves them to the kernels; and the numpy backend's
images with each sampler agree with the independent sampler's (block z-test)."""

from __future__ import annotations

import numpy as np
import pytest

import rtpy
from rtpy import sampler as scalar
from rtpy.numpy_backend import renderer
from rtpy.numpy_backend import sampler as batch
from rtpy.numpy_backend.sampler import BATCH_SAMPLERS, LaneSampler, first_hit_generator
from rtpy.sampler import BRDF, LENS, LIGHT, LIGHT_CHOICE, PIXEL, SAMPLERS

from ..test_sampler import agrees_with_independent
from ..tiers import slow_except

ALPHA = 1e-3
PIXELS = np.repeat(np.arange(0, 700, 97), 10)
INDICES = np.tile(np.arange(10), len(PIXELS) // 10)


@pytest.mark.parametrize("name", list(SAMPLERS))
def test_values_equal_the_scalar_samplers(name):
    one, many = SAMPLERS[name](seed=7, spp=10), BATCH_SAMPLERS[name](seed=7, spp=10)
    keys = list(zip(PIXELS.tolist(), INDICES.tolist(), strict=True))
    for dim in (PIXEL, LENS, LIGHT_CHOICE, LIGHT, BRDF):
        ones = [one.value_1d(p, i, dim) for p, i in keys]
        twos = np.array([one.value_2d(p, i, dim) for p, i in keys]).T
        assert np.array_equal(many.value_1d(PIXELS, INDICES, dim), ones)
        assert np.array_equal(many.value_2d(PIXELS, INDICES, dim), twos)


def test_building_blocks_equal_the_scalar_ones():
    v = np.array([0, 1, 7, 0x12345678, 0xFFFFFFFF], dtype=np.uint32)
    seeds = np.array([0, 3, 0xCAFEF00D, 99, 0xFFFFFFFF], dtype=np.uint32)
    assert batch.reverse_bits32(v).tolist() == [scalar.reverse_bits32(int(x)) for x in v]
    assert batch.owen_scramble(v, seeds).tolist() == [
        scalar.owen_scramble(int(x), int(s)) for x, s in zip(v, seeds, strict=True)
    ]
    assert [list(a) for a in zip(*batch.sobol_2d(v), strict=True)] == [
        list(scalar.sobol_2d(int(x))) for x in v
    ]
    for n in (1, 4, 17, 40):  # 40: the swap bits from a hash (n > 32)
        for p in (3, 0xFEDCBA9876543210):
            assert batch.permute(np.arange(n), n, np.uint64(p)).tolist() == [
                scalar.permute(k, n, p) for k in range(n)
            ]
    # A pixel's samples share p: its hashes come from a table made once per run of equal
    # p, or per sample when the runs are short. Both give the scalar permutation.
    rng = np.random.default_rng(5)
    for n, run in ((4, 1), (4, 5), (40, 1), (40, 3), (100, 1), (100, 8)):
        p = np.repeat(rng.integers(0, 2**63, 60, dtype=np.uint64), run)
        k = rng.integers(0, n, p.size)
        assert batch.permute(k, n, p).tolist() == [
            scalar.permute(int(a), n, int(b)) for a, b in zip(k, p, strict=True)
        ]
    assert batch.hash_key(3, np.arange(4), 5).tolist() == [
        scalar.hash_key(3, k, 5) for k in range(4)
    ]
    n = np.arange(1, 300)
    for u in (0.0, 0.5, 1.0 - 2.0**-53):
        assert batch.jittered(n - 1, u, n).tolist() == [
            scalar.jittered(int(k) - 1, u, int(k)) for k in n
        ]


def test_the_largest_32_bit_fraction_stays_below_one(monkeypatch):
    """A scrambled Sobol coordinate of 2^32 - 1 (one in 2^32 of them) is a float below 1."""
    monkeypatch.setattr(batch, "owen_scramble", lambda v, seed: np.full_like(v, 0xFFFFFFFF))
    sobol = BATCH_SAMPLERS["sobol"](seed=1)
    assert sobol.value_1d(PIXELS, INDICES, LIGHT_CHOICE).max() < 1.0
    assert sobol.value_2d(PIXELS, INDICES, LIGHT).max() < 1.0


def test_sobol_refuses_indices_past_2_to_the_32():
    with pytest.raises(ValueError, match="index"):  # would repeat point 0
        BATCH_SAMPLERS["sobol"]().value_1d(np.zeros(2, dtype=int), np.array([0, 2**32]), 0)


def test_passes_take_each_sample_index_once(monkeypatch):
    """Units of 8 camera paths: spp 4 over 4 x 4 pixels takes 4 passes, and across them
    the sampler is asked for each pixel's samples 0, 1, 2, 3 once each
    (Unit.first_sample), so a pixel's samples are the same points however they are
    split."""
    asked = []

    class Recording(BATCH_SAMPLERS["stratified"]):
        def value_2d(self, pixel, index, dim):
            if dim == PIXEL:
                asked.extend(zip(pixel.tolist(), index.tolist(), strict=True))
            return super().value_2d(pixel, index, dim)

    monkeypatch.setitem(BATCH_SAMPLERS, "stratified", Recording)
    monkeypatch.setattr(renderer, "MAX_RAYS", 8)
    scene = rtpy.load_scene("cornell")
    camera = scene.camera.with_width(4)
    settings = {"spp": 4, "sampler": "stratified", "integrator": "jittered"}
    rtpy.render(scene, camera=camera, backend="numpy", **settings)
    pixels = range(camera.width * camera.height)
    assert sorted(asked) == [(p, k) for p in pixels for k in range(4)]


def make_lane_sampler(seed: int = 2) -> LaneSampler:
    return LaneSampler(
        BATCH_SAMPLERS["sobol"](seed, 10), PIXELS, INDICES, np.random.default_rng(seed)
    )


def test_lane_sampler_serves_whole_calls_and_leaves_parts_independent():
    sobol = BATCH_SAMPLERS["sobol"](2, 10)
    camera = make_lane_sampler().camera()
    assert np.array_equal(camera.random((2, len(PIXELS))), sobol.value_2d(PIXELS, INDICES, PIXEL))
    assert np.array_equal(camera.random((2, len(PIXELS))), sobol.value_2d(PIXELS, INDICES, LENS))
    lanes = np.array([3, 5, 8, 13])
    hit = make_lane_sampler().first_hit(lanes)
    p, i = PIXELS[lanes], INDICES[lanes]
    assert np.array_equal(hit.random(4), sobol.value_1d(p, i, LIGHT_CHOICE))
    three = hit.random((3, 4))  # a 1D dimension, then a 2D one
    assert np.array_equal(three[0], sobol.value_1d(p, i, LIGHT))
    assert np.array_equal(three[1:], sobol.value_2d(p, i, BRDF))
    # A call for part of the lanes, and the sampler without lanes: the generator's numbers.
    twin = np.random.default_rng(2)
    assert np.array_equal(hit.random((2, 3)), twin.random((2, 3)))
    assert np.array_equal(make_lane_sampler().random(5), np.random.default_rng(2).random(5))
    assert make_lane_sampler().integers(10, size=3).tolist() == (
        np.random.default_rng(2).integers(10, size=3).tolist()
    )


def test_first_hit_generator():
    rng = np.random.default_rng(0)
    assert first_hit_generator(rng, np.arange(3), 1) is rng
    lane = make_lane_sampler()
    assert first_hit_generator(lane, np.arange(3), 2) is lane.generator
    assert first_hit_generator(lane, np.arange(3), 1).dim == LIGHT_CHOICE


@pytest.mark.parametrize(
    "sampler, integrator",
    slow_except(
        [(s, i) for s in ("stratified", "sobol") for i in ("shading", "direct", "path")],
        ("sobol", "direct"),
    ),
)
def test_images_agree_with_the_independent_sampler(sampler, integrator):
    """Cornell box (area light, diffuse walls): the mean of 8 renders with each sampler
    against 8 with the independent one, each side's variance from its own spread."""
    agrees_with_independent("numpy", sampler, integrator, width=16)


@pytest.mark.slow
def test_images_are_the_same_for_any_worker_count(sampler="sobol"):
    """Several units of work (48 x 48 pixels x 32 spp is more than one unit holds); the
    renderer treats every sampler alike (the scalar backend's test takes the
    stratified one)."""
    scene = rtpy.load_scene("cornell")
    settings = {"width": 48, "spp": 32, "sampler": sampler, "integrator": "path", "seed": 3}
    one = rtpy.render(scene, backend="numpy", workers=1, **settings).linear
    two = rtpy.render(scene, backend="numpy", workers=2, **settings).linear
    assert np.array_equal(one, two)
