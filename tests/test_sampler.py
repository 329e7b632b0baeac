"""The samplers (rtpy/sampler.py): their points are stratified as each promises,
uniform and independent across pixels and dimensions, deterministic per seed, and the
images they render are unbiased (block z-tests against the closed-form scenes)."""

from __future__ import annotations

import collections
import itertools
import math
import random

import numpy as np
import pytest

import rtpy
from rtpy.sampler import (
    BRDF,
    LAYOUT,
    LENS,
    LIGHT,
    LIGHT_CHOICE,
    PIXEL,
    SAMPLERS,
    IndependentSampler,
    SobolSampler,
    StratifiedSampler,
    grid_2d,
    jittered,
    owen_scramble,
    permute,
    reverse_bits32,
    sobol_2d,
)
from rtpy.testing.analytic_scenes import analytic_scene
from rtpy.testing.statistics import block_z_test, bonferroni_alpha, chi2_sf, normal_quantile

from .tiers import slow_except

ALPHA = 1e-3
STRATIFYING = ("stratified", "sobol")


def points_2d(sampler, pixel: int, dim: int, n: int) -> np.ndarray:
    return np.array([sampler.value_2d(pixel, i, dim) for i in range(n)])


# --- the building blocks ---------------------------------------------------------------


@pytest.mark.parametrize("n", [1, 2, 3, 5, 16, 17, 32, 33, 100])
def test_permute_is_a_permutation(n):
    for p in (0, 1, 0xDEADBEEF, 2**64 - 1):
        assert sorted(permute(i, n, p) for i in range(n)) == list(range(n))


def even_counts_p(counts: np.ndarray) -> float:
    """p-value of counts over cells that are equally likely (Pearson's chi-square)."""
    expected = counts.sum() / len(counts)
    return chi2_sf(float(((counts - expected) ** 2 / expected).sum()), len(counts) - 1)


def permutation_p(perms: list[tuple[int, ...]], n: int) -> float:
    """p-value of the permutations `perms` of range(n) being uniform over all n! (a
    chi-square test over the n! cells)."""
    counts = collections.Counter(perms)
    return even_counts_p(np.array([counts[q] for q in itertools.permutations(range(n))]))


def test_permute_gives_every_permutation_alike():
    """Over random seeds, each of the n! permutations comes out equally often (20 times
    each expected). A hashed bijection of the next power of two (Kensler's) gives only 8
    of the 24 permutations of 4 elements."""
    rng = random.Random(6)
    ns = (3, 4, 5)
    for n in ns:
        seeds = [rng.getrandbits(64) for _ in range(20 * math.factorial(n))]
        perms = [tuple(permute(i, n, p) for i in range(n)) for p in seeds]
        assert permutation_p(perms, n) > bonferroni_alpha(ALPHA, len(ns)), n


def test_reverse_bits32():
    assert reverse_bits32(1) == 1 << 31
    assert reverse_bits32(0b1011) == 0b1101 << 28
    assert all(reverse_bits32(reverse_bits32(v)) == v for v in (0, 7, 0x12345678, 0xFFFFFFFF))


def test_sobol_2d_is_the_sequence():
    """The first points of the 2D Sobol sequence, and the generator matrices applied
    bit by bit: the identity mirrored for x, columns v_{k+1} = v_k xor (v_k >> 1) for y."""
    first = [sobol_2d(i) for i in range(4)]
    assert [(x / 2**32, y / 2**32) for x, y in first] == [
        (0.0, 0.0),
        (0.5, 0.5),
        (0.25, 0.75),
        (0.75, 0.25),
    ]
    for index in (5, 1000, 0x9ABCDEF0, 0xFFFFFFFF):
        x = y = 0
        vy = 1 << 31
        for k in range(32):
            if index >> k & 1:
                x ^= 1 << (31 - k)
                y ^= vy
            vy ^= vy >> 1
        assert sobol_2d(index) == (x, y)


def test_owen_scramble_maps_aligned_blocks_to_aligned_blocks():
    """A nested scramble flips each bit by the bits above it: fractions that share
    their top bits still share them, and the 2^k cells of the top k bits are permuted."""
    for k in (1, 3, 6):
        for seed in (0, 12345, 0xCAFEF00D):
            assert len({owen_scramble(v, seed) >> k for v in range(2**k)}) == 1
            cells = {owen_scramble(c << (32 - k), seed) >> (32 - k) for c in range(2**k)}
            assert cells == set(range(2**k))


# --- stratification --------------------------------------------------------------------


@pytest.mark.parametrize("m", [0, 2, 4, 6])
def test_sobol_points_are_a_0_m_2_net(m):
    """Each prefix of 2^m points has one point in every elementary interval of area
    2^-m, for every shape (2^a x 2^(m-a) cells), in every pixel and dimension."""
    sampler = SobolSampler(seed=3)
    for pixel, dim in ((0, PIXEL), (41, LIGHT), (7, BRDF)):
        pts = points_2d(sampler, pixel, dim, 2**m)
        for a in range(m + 1):
            cells = (pts[:, 0] * 2**a).astype(int) * 2 ** (m - a)
            cells += (pts[:, 1] * 2 ** (m - a)).astype(int)
            assert sorted(cells) == list(range(2**m)), (pixel, dim, a)
        ones = sorted(np.array([sampler.value_1d(pixel, i, dim) for i in range(2**m)]) * 2**m)
        assert [int(v) for v in ones] == list(range(2**m))


@pytest.mark.parametrize("spp", [1, 4, 9, 16, 10, 7])
def test_stratified_has_one_point_per_stratum(spp):
    """A square spp: every cell of the sqrt(spp) grid once; otherwise spp different
    cells of the nx x ny grid. 1D: every one of the spp strata once."""
    sampler = StratifiedSampler(seed=5, spp=spp)
    nx, ny = grid_2d(spp)
    assert nx * ny >= spp and (nx - 1) * ny < spp
    for pixel, dim in ((0, PIXEL), (13, LIGHT)):
        pts = points_2d(sampler, pixel, dim, spp)
        assert pts.min() >= 0.0 and pts.max() < 1.0
        cells = (pts[:, 1] * ny).astype(int) * nx + (pts[:, 0] * nx).astype(int)
        assert len(set(cells)) == spp
        if nx * ny == spp:
            assert sorted(cells) == list(range(spp))
        ones = np.array([sampler.value_1d(pixel, i, dim) for i in range(spp)])
        assert sorted((ones * spp).astype(int)) == list(range(spp))


def test_stratified_pairs_the_strata_of_two_dimensions_at_random():
    """Padding, spp 4: the permutation that takes each sample's stratum in one dimension
    to its stratum in another is, over pixels, uniform over all 24 (20 pixels each
    expected). A restricted family of permutations ties the dimensions together: with
    Kensler's, the column of the pixel position fixes the column of the light sample
    (same or opposite for all four samples), and one permutation for every dimension
    pairs stratum k with stratum k."""
    sampler = StratifiedSampler(seed=8, spp=4)
    pixels = range(480)

    def strata(pixel: int, dim: int) -> list[int]:
        """Each sample's stratum: its cell of the 2 x 2 grid, or of the 4 strata (1D)."""
        if dim == LIGHT_CHOICE:
            return [int(sampler.value_1d(pixel, k, dim) * 4) for k in range(4)]
        return [int(y * 2) * 2 + int(x * 2) for x, y in points_2d(sampler, pixel, dim, 4)]

    cells = {dim: [strata(p, dim) for p in pixels] for dim in (PIXEL, LIGHT_CHOICE, LIGHT, BRDF)}
    pairs = ((PIXEL, LIGHT_CHOICE), (PIXEL, LIGHT), (LIGHT, BRDF))
    for a, b in pairs:
        perms = [
            tuple(sb[sa.index(c)] for c in range(4))
            for sa, sb in zip(cells[a], cells[b], strict=True)
        ]
        assert permutation_p(perms, 4) > bonferroni_alpha(ALPHA, len(pairs)), (a, b)


# --- uniform and independent -----------------------------------------------------------


def chi_square_p(values: np.ndarray, bins: int) -> float:
    """p-value of values (uniform in [0, 1)^k if all is well) falling evenly into
    bins^k equal cells."""
    values = np.atleast_2d(values)
    cells = np.zeros(len(values[0]), dtype=np.int64)
    for row in values:
        cells = cells * bins + np.minimum((row * bins).astype(np.int64), bins - 1)
    return even_counts_p(np.bincount(cells, minlength=bins ** len(values)))


def test_the_last_stratum_stays_below_one():
    """(k + u) / n with k = n - 1 and u the largest float below 1 rounds to exactly
    1.0 for most n; every value a sampler gives is in [0, 1) (a light choice or an
    inverse CDF at 1.0 would index past its table)."""
    u = 1.0 - 2.0**-53
    last = [jittered(n - 1, u, n) for n in range(1, 300)]
    assert max(last) < 1.0
    assert last[2] == 1.0 - 2.0**-53  # n = 3 hits the bound: (2 + u) / 3 rounds to 1


def coordinates(sampler, pixel: int, index: int) -> dict[tuple[int, int], float]:
    """Every number of a pixel sample that LAYOUT serves, by (dimension, coordinate)."""
    values = {}
    for dim, size in LAYOUT:
        if size == 1:
            values[dim, 0] = sampler.value_1d(pixel, index, dim)
        else:
            values[dim, 0], values[dim, 1] = sampler.value_2d(pixel, index, dim)
    return values


@pytest.mark.parametrize("name", list(SAMPLERS))
def test_values_are_uniform_and_independent_across_pixels_and_dimensions(name):
    """Sample 2 of 1024 pixels: each number the layout serves is uniform (32 bins, finer
    than the 4 strata: a stratum's points must spread over all of it), and every two of
    them are independent (4 x 4 bins). A sampler that shares its scrambling between
    pixels gives every pixel the same point; two dimensions (or the x and y of one)
    that share a seed or a jitter give related numbers."""
    sampler = SAMPLERS[name](seed=9, spp=4)
    samples = [coordinates(sampler, p, 2) for p in range(1024)]
    values = {c: np.array([v[c] for v in samples]) for c in samples[0]}
    pairs = list(itertools.combinations(values, 2))
    alpha = bonferroni_alpha(ALPHA, len(values) + len(pairs))
    for c, v in values.items():
        assert chi_square_p(v, 32) > alpha, c
    for a, b in pairs:
        assert chi_square_p(np.array([values[a], values[b]]), 4) > alpha, (a, b)


@pytest.mark.parametrize("name", STRATIFYING)
def test_two_dimensions_of_a_pixel_are_paired_no_worse_than_independent_numbers(name):
    """Padding, spp 4: c, the number of a pixel's samples in the lower half of two
    dimensions at once, is 1 on average; over pixels E (c - 1)^2 must be below 3/4, its
    value for independent numbers (binomial: 4 x 1/4 x 3/4). A uniformly random
    pairing of stratified values gives 1/3, Burley's nested shuffle 1/2; dimensions
    whose strata are tied together (no shuffle, one shuffle for all dimensions,
    permutations from a small family) give c = 0 or 2 in most pixels, near 1. One-sided
    z-test of the mean over 600 pixels, the variance from their spread."""
    sampler = SAMPLERS[name](seed=10, spp=4)
    pixels = [[coordinates(sampler, p, k) for k in range(4)] for p in range(600)]
    pairs = [((PIXEL, 0), (LIGHT, 0)), ((LIGHT_CHOICE, 0), (LIGHT, 0)), ((PIXEL, 1), (BRDF, 1))]
    z = normal_quantile(2.0 * bonferroni_alpha(ALPHA, len(pairs)))  # one-sided
    for a, b in pairs:
        c = np.array([sum(v[a] < 0.5 and v[b] < 0.5 for v in samples) for samples in pixels])
        d = (c - 1.0) ** 2
        assert d.mean() + z * d.std(ddof=1) / math.sqrt(len(d)) < 0.75, (a, b, d.mean())


def test_the_largest_32_bit_fraction_stays_below_one(monkeypatch):
    """A scrambled Sobol coordinate of 2^32 - 1 (one in 2^32 of them) is a float below 1."""
    monkeypatch.setattr(rtpy.sampler, "owen_scramble", lambda v, seed: 0xFFFFFFFF)
    sampler = SobolSampler(seed=1)
    assert max(sampler.value_1d(3, 0, LIGHT_CHOICE), *sampler.value_2d(3, 0, LIGHT)) < 1.0


@pytest.mark.parametrize("name", list(SAMPLERS))
def test_values_are_deterministic_per_seed(name):
    a, b, c = SAMPLERS[name](1, 8), SAMPLERS[name](1, 8), SAMPLERS[name](2, 8)
    key = (17, 5, LIGHT)
    assert a.value_2d(*key) == b.value_2d(*key) != c.value_2d(*key)


def test_random_serves_the_layout_then_the_fallback():
    fallback, twin = random.Random(4), random.Random(4)
    sampler = SobolSampler(seed=2, spp=8, fallback=fallback)
    sampler.start_pixel_sample(30, 3)
    draws = [sampler.random() for _ in range(9)]
    assert draws[:2] == list(sampler.value_2d(30, 3, PIXEL))
    assert draws[2] == sampler.value_1d(30, 3, LIGHT_CHOICE)
    assert draws[3:5] == list(sampler.value_2d(30, 3, LIGHT))
    assert draws[5:7] == list(sampler.value_2d(30, 3, BRDF))
    assert draws[7:] == [twin.random(), twin.random()]
    lens = StratifiedSampler(seed=2, spp=8, defocus=True)
    lens.start_pixel_sample(30, 3)
    draws = [lens.random() for _ in range(5)]
    assert draws[2:4] == list(lens.value_2d(30, 3, LENS))
    assert draws[4] == lens.value_1d(30, 3, LIGHT_CHOICE)
    sampler.start_pixel_sample(30, 3)
    assert sampler.get_2d() == sampler.value_2d(30, 3, 0)
    assert sampler.get_1d() == sampler.value_1d(30, 3, 1)


def test_bad_arguments_are_refused():
    with pytest.raises(ValueError, match="spp"):
        StratifiedSampler(spp=0)
    with pytest.raises(ValueError, match="index"):
        StratifiedSampler(spp=4).value_1d(0, 4, 0)
    with pytest.raises(ValueError, match="index"):  # would repeat point 0
        SobolSampler().value_2d(0, 2**32, 0)
    with pytest.raises(ValueError, match="sampler"):
        rtpy.RenderSettings(sampler="halton")
    assert IndependentSampler(1).value_1d(0, 0, 0) != IndependentSampler(1).value_1d(1, 0, 0)


# --- renders ---------------------------------------------------------------------------


def unbiased_check(backend: str, sampler: str, scene: str, integrator: str, spp: int, seeds: int):
    """block_z_test of the mean of independent renders (different seeds) against the
    closed-form image, the variance from their spread."""
    a = analytic_scene(scene)
    camera = a.camera.with_width(8)
    depth = 2 if integrator == "direct" else a.settings.max_depth
    exact, mask = a.exact(camera, depth)
    settings = {"integrator": integrator, "sampler": sampler, "spp": spp}
    settings.update(camera=camera, backend=backend, max_depth=a.settings.max_depth)
    images = np.array([rtpy.render(a.scene, seed=s, **settings).linear for s in range(seeds)])
    images[:, ~mask] = exact[~mask]
    mean, var = images.mean(axis=0), images.var(axis=0, ddof=1) / seeds
    test = block_z_test(mean, var, exact, np.zeros_like(exact), ALPHA, block=4)
    assert test.passed, test.worst("the closed form")


# Not a power of two nor a square (the samplers' general case), and not a multiple of 4:
# the sky band covers just under a quarter of the cosine-weighted hemisphere, so with 4
# stratified samples nearly every pixel would see it exactly once, the spread across
# seeds would be almost always 0, and the z-test's normal approximation would not hold.
SPP = 5
CASES = [
    (backend, sampler, scene)
    for backend in ("numpy", "scalar")
    for sampler in STRATIFYING
    for scene in ("plane_sphere_light", "plane_point_light", "plane_sky_band")
]


@pytest.mark.parametrize(
    "backend, sampler, scene",
    slow_except(
        CASES, ("numpy", "sobol", "plane_sphere_light"), ("numpy", "stratified", "plane_sky_band")
    ),
)
def test_renders_are_unbiased_against_the_closed_form(backend, sampler, scene):
    seeds = 16 if backend == "numpy" else 8
    unbiased_check(backend, sampler, scene, "direct", SPP, seeds)


@pytest.mark.slow
@pytest.mark.parametrize("sampler", STRATIFYING)
def test_path_renders_are_unbiased_against_the_closed_form(sampler):
    unbiased_check("numpy", sampler, "plane_sphere_light", "path", SPP, 16)


def agrees_with_independent(backend: str, sampler: str, integrator: str, width: int) -> None:
    """Cornell box (area light, diffuse walls), 4 spp: the mean of 8 renders with
    `sampler` against 8 with the independent one, block by block, each side's
    variance from its own spread."""
    scene = rtpy.load_scene("cornell")
    settings = {"width": width, "spp": 4, "integrator": integrator, "backend": backend}
    a, b = (
        np.array([rtpy.render(scene, sampler=s, seed=k, **settings).linear for k in seeds])
        for s, seeds in ((sampler, range(8)), ("independent", range(100, 108)))
    )
    var_a, var_b = a.var(axis=0, ddof=1) / len(a), b.var(axis=0, ddof=1) / len(b)
    test = block_z_test(a.mean(axis=0), var_a, b.mean(axis=0), var_b, ALPHA, block=4)
    assert test.passed, test.worst("the independent sampler")


@pytest.mark.slow
def test_scalar_images_agree_with_the_independent_sampler():
    agrees_with_independent("scalar", "sobol", "path", width=8)


@pytest.mark.slow
def test_scalar_images_are_the_same_for_any_worker_count(sampler="stratified"):
    """Several tiles and batches; the renderer treats every sampler alike (the numpy
    backend's test takes the Sobol sampler)."""
    scene = rtpy.load_scene("cornell")
    settings = {"width": 24, "spp": 2, "sampler": sampler, "integrator": "path", "seed": 4}
    one = rtpy.render(scene, workers=1, **settings).linear
    two = rtpy.render(scene, workers=2, **settings).linear
    assert np.array_equal(one, two)


def test_batches_take_each_sample_index_once(monkeypatch):
    """The renderer splits spp 4 into 4 batches (units of work); across them the sampler
    is asked for each pixel's samples 0, 1, 2, 3 once each (Unit.first_sample), so a
    pixel's samples are the same points however they are split."""
    asked = []

    class Recording(StratifiedSampler):
        def value_2d(self, pixel, index, dim):
            if dim == PIXEL:
                asked.append((pixel, index))
            return super().value_2d(pixel, index, dim)

    monkeypatch.setitem(SAMPLERS, "stratified", Recording)
    scene = rtpy.load_scene("cornell")
    camera = scene.camera.with_width(4)
    rtpy.render(scene, camera=camera, spp=4, sampler="stratified", integrator="jittered")
    pixels = range(camera.width * camera.height)
    assert sorted(asked) == [(p, k) for p in pixels for k in range(4)]


def test_independent_is_the_default():
    assert rtpy.RenderSettings().sampler == "independent"
