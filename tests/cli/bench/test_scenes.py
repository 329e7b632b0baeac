"""rtpy.cli.bench.scenes: the integrator variants, and the scenes with their references."""

from __future__ import annotations

import pytest

from rtpy.cli.bench.run import run_bench
from rtpy.cli.bench.scenes import ALL_VARIANTS, VARIANTS, effective_depth, load_bench_scene
from rtpy.integrators import INTEGRATORS
from rtpy.render_settings import RenderSettings
from rtpy.testing.analytic_scenes import ANALYTIC_SCENES, analytic_scene


def test_every_variant_is_valid_render_settings():
    for name, settings in ALL_VARIANTS.items():
        assert settings["integrator"] in INTEGRATORS, name
        RenderSettings().with_overrides(**settings)  # raises on a bad setting
    assert effective_depth("direct", 8) == 2  # "direct" is path tracing at depth 2
    assert {effective_depth(v, 8) for v in VARIANTS if v != "direct"} == {8}


@pytest.mark.parametrize("name", sorted(ANALYTIC_SCENES))
def test_an_analytic_scene_is_measured_against_its_closed_form(name):
    bs = load_bench_scene(name, width=8)
    a = analytic_scene(name)
    assert bs.name == name and bs.camera.width == 8
    assert (bs.max_depth, bs.russian_roulette) == (
        a.settings.max_depth,
        a.settings.russian_roulette,
    )
    ref = bs.reference_for(bs.max_depth)
    assert ref.exact and ref.image.shape == (bs.camera.height, 8, 3)
    assert ref.mask.any() and name in ref.source


def test_a_scene_file_is_measured_against_a_rendered_reference(tmp_path):
    """A bundled scene by name, at the width asked for (its own without one); its
    reference is rendered (by the "numpy" backend) when first asked for, and cached."""
    bs = load_bench_scene("week05_point_light", width=6, cache=tmp_path, reference_spp=4)
    assert bs.name == "week05_point_light" and bs.camera.width == 6
    assert load_bench_scene("week05_point_light", width=None).camera.width > 6
    ref = bs.reference_for(2)
    assert not ref.exact and ref.image.shape == (bs.camera.height, 6, 3)
    assert "numpy" in ref.source
    assert list(tmp_path.glob("week05_point_light-w6-d2*.npz"))


def test_stop_criteria_show_the_energy_lost_by_a_cap_and_none_by_roulette():
    """Inside the glowing sphere (exact image Le / (1 - rho), depth 200) a cap of three
    segments loses energy and is flagged as biased; the lecture's fixed p_RR and the
    throughput roulette are not."""
    result = run_bench(
        ["glowing_furnace"],
        variants=("path-cap3", "path-fixed-rr", "path-mis"),
        spps=(4, 16),
        repeats=2,
        width=12,
        log=lambda _: None,
    )
    flagged = {lv.integrator: lv.significant for lv in result.levels if lv.spp == 16}
    assert flagged == {"path-cap3": True, "path-fixed-rr": False, "path-mis": False}
    assert all(lv.rel_bias < -0.05 for lv in result.levels if lv.integrator == "path-cap3")
