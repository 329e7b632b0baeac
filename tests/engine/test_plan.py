"""rtpy.engine.plan: passes of 1, 1, 2, 4, ... samples per pixel up to the cap, cut into
units of at most a backend's paths, the same for any spp up to where it ends."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from rtpy.engine.plan import MAX_PASS_SPP, Plan, pass_sizes


@pytest.mark.parametrize(
    "spp,cap,sizes",
    [
        (1, 16, [1]),
        (2, 16, [1, 1]),
        (5, 16, [1, 1, 2, 1]),
        (64, 16, [1, 1, 2, 4, 8, 16, 16, 16]),
        (100, 28, [1, 1, 2, 4, 8, 16, 28, 28, 12]),
        (7, 1, [1] * 7),
    ],
)
def test_passes_double_up_to_the_cap(spp, cap, sizes):
    assert pass_sizes(spp, cap) == sizes


@given(st.integers(1, 5000), st.integers(1, 64))
def test_each_pass_holds_at_most_the_samples_before_it(spp, cap):
    """So the first image comes after one sample per pixel and each later pass takes
    no longer than all the passes before it; the passes of a smaller spp are the
    first ones of a larger spp's, up to its last."""
    sizes = pass_sizes(spp, cap)
    assert sum(sizes) == spp and sizes[0] == 1
    for k, size in enumerate(sizes[1:], 1):
        assert 1 <= size <= min(cap, sum(sizes[:k]))
    longer = pass_sizes(spp + 37, cap)
    assert longer[: len(sizes) - 1] == sizes[:-1]


@settings(max_examples=50)
@given(st.integers(1, 120), st.integers(1, 30), st.integers(1, 100), st.integers(1, 5000))
def test_units_cover_every_pixel_once_per_pass_within_the_path_budget(
    width, height, spp, paths_per_unit
):
    plan = Plan(width, height, spp, paths_per_unit)
    counts = np.zeros((height, width), dtype=int)
    first = np.zeros((height, width), dtype=int)  # each pixel's next sample index
    for unit in plan.units():
        region = (slice(unit.y0, unit.y1), slice(unit.x0, unit.x1))
        assert (first[region] == unit.first_sample).all()  # samples in order, none twice
        counts[region] += unit.spp
        first[region] += unit.spp
        assert unit.paths <= max(paths_per_unit, unit.spp)  # a pixel is the least
    np.testing.assert_array_equal(counts, spp)
    assert plan.count_units() == sum(1 for _ in plan.units())
    assert [u.batch for u in plan.units()] == sorted(u.batch for u in plan.units())


@pytest.mark.parametrize(
    "width,height,spp,passes,pass_spp,units_in_the_last",
    [
        (1920, 1080, 1, 1, 1, 32),  # more pixels than a unit holds paths: 32 bands
        (256, 256, 64, 8, 16, 16),  # 1, 1, 2, 4, 8, 16, 16, 16: 16 bands of 16 rows
        (256, 256, 4096, 260, 16, 16),  # 6 passes to the cap, then 254 of 16
        (48, 48, 20000, 720, 28, 1),  # a small image: 28 spp fill a unit of 2304 pixels
    ],
)
def test_plans_as_docs_numpy_backend_describes_them(
    width, height, spp, passes, pass_spp, units_in_the_last
):
    """docs/numpy-backend.md's examples, counted by hand, for units of 65,536 paths."""
    plan = Plan(width, height, spp, 65536)
    assert len(plan.passes) == passes and max(plan.passes) == pass_spp
    assert len(plan.units_of(passes - 1)) == units_in_the_last


def test_a_pass_over_a_small_image_fills_a_unit():
    assert Plan(48, 48, 20000, 65536).cap == 65536 // (48 * 48)
    assert Plan(256, 256, 64, 65536).cap == MAX_PASS_SPP


def test_whole_passes_are_found_by_their_samples():
    plan = Plan(4, 4, 64, 256)
    assert [plan.samples_after(k) for k in range(len(plan.passes) + 1)] == [
        0, 1, 2, 4, 8, 16, 32, 48, 64
    ]  # fmt: skip
    assert plan.passes_holding(16) == 5 and plan.passes_holding(3) is None


def test_bands_are_as_equal_as_whole_numbers_allow():
    """37 rows of 100 pixels in units of at most 1,000 paths at 1 spp: four bands of
    10, 10, 10 and 7 rows; a row of 100 pixels at 8 spp in units of 500 paths (62
    pixels): two pieces of 50, not 62 and 38."""
    rows = [u.y1 - u.y0 for u in Plan(100, 37, 1, 1000).units_of(0)]
    assert rows == [10, 10, 10, 7]
    plan = Plan(100, 1, 16, 500)
    assert plan.passes[4] == 8 and [u.x1 - u.x0 for u in plan.units_of(4)] == [50, 50]
