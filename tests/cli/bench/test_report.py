"""rtpy.cli.bench.report: the printed tables, the files, and the generated section of
docs/bench.md."""

from __future__ import annotations

import csv
import json
import math
import re
from dataclasses import replace
from pathlib import Path

import pytest

from rtpy.cli.bench.convergence import BenchResult, Level
from rtpy.cli.bench.machine import machine
from rtpy.cli.bench.report import (
    GENERATED_BEGIN,
    GENERATED_END,
    draw,
    findings,
    format_doc_section,
    format_efficiency,
    format_sampler_efficiency,
    format_series,
    format_table,
    machine_lines,
    plot_notes,
    replace_generated,
    sampler_gains,
    write_outputs,
)
from rtpy.cli.bench.run import run_bench

DOC = Path(__file__).resolve().parents[3] / "docs" / "bench.md"
PERFORMANCE_DOC = DOC.parent / "performance.md"  # the engine's benchmarks


@pytest.fixture(scope="module")
def result():
    """Two scenes (one exact, one noisy), both backends, two variants, two levels."""
    return run_bench(
        ["furnace", "plane_point_light"],
        ("numpy", "scalar"),
        ("path-brdf", "path-mis"),
        (1, 4),
        repeats=2,
        width=8,
        log=lambda _: None,
    )


def test_tables_have_a_row_per_level_and_per_series(result):
    table = format_table(result).splitlines()
    assert len(table) == 1 + len(result.levels) == 1 + 2 * 2 * 2 * 2
    assert table[0].split()[:5] == ["scene", "backend", "integrator", "sampler", "spp"]
    series = format_series(result, markdown=True).splitlines()
    rows = [line for line in series if line.startswith("| ") and "---" not in line]
    assert len(rows) == 1 + len(result.fits) == 1 + 8
    assert all(row.count("|") == 13 for row in rows)  # 12 columns
    furnace = [row for row in rows if row.startswith("| furnace ")]
    assert furnace and all("| exact |" in row for row in furnace)
    assert series[-1].startswith("slope: of log MSE against log spp")


def converged(result: BenchResult) -> BenchResult:
    """result with every fitted slope -1 +- 0.01 (a run this small cannot fit slopes)."""
    fits = [f if f.slope is None else replace(f, slope=-1.0, slope_se=0.01) for f in result.fits]
    return replace(result, fits=fits)


def test_findings_give_the_bias_the_slopes_and_the_speed_ratio(result):
    bias, slopes, speed = findings(converged(result))
    assert bias == "- Bias: no level is significantly biased."
    assert slopes == (
        "- Slopes: 4 of 4 series are measured to ± 0.0375 or better; "
        "all of them are -1 within 0.15."
    )  # the furnace's 4 series have no error, so no slope
    assert re.fullmatch(r"- Speed: the numpy backend traces \d+-\d+ times the scalar .*", speed)


def test_findings_report_a_biased_level_a_wrong_slope_and_an_uncertain_one(result):
    good = converged(result)
    level = replace(good.levels[-1], significant=True, bias_z=-5.0)
    biased = replace(good, levels=[*good.levels[:-1], level])
    assert findings(biased)[0].startswith(
        f"- Bias: significant at {level.scene}/{level.backend}/{level.integrator} "
        f"at {level.spp} spp (z = -5.0) (threshold"
    )
    fits = list(good.fits)
    fits[-1] = replace(fits[-1], slope=-0.5)  # measured precisely, and wrong
    fits[-2] = replace(fits[-2], slope=-0.5, slope_se=0.3)  # too uncertain to judge
    slopes = findings(replace(good, fits=fits))[1]
    f, g = fits[-1], fits[-2]
    assert f"off -1 by more than 0.15: {f.scene}/{f.backend}/{f.integrator} (-0.50)" in slopes
    assert slopes.endswith(
        f"Too few levels or too noisy to judge: {g.scene}/{g.backend}/{g.integrator}."
    )
    assert "3 of 4 series" in slopes
    vague = replace(good, fits=[replace(f, slope_se=0.3) for f in good.fits])
    assert findings(vague)[1].startswith("- Slopes: no slope is measured to ± 0.0375 or better. ")


def test_efficiency_table_ranks_the_variants_of_each_scene_and_backend(result):
    lines = format_efficiency(converged(result)).splitlines()
    assert lines[0] == (
        "| scene | path tracing, numpy: efficiency relative to the best "
        "| path tracing, scalar: efficiency relative to the best |"
    )
    (row,) = lines[2:]  # the furnace has no error: only the noisy scene
    cells = row.strip("| ").split(" | ")
    assert cells[0] == "plane_point_light"
    for cell in cells[1:]:
        ranked = [part.rsplit(" ", 1) for part in cell.split(", ")]
        assert {v for v, _ in ranked} == {"path-brdf", "path-mis"}
        ratios = [float(r) for _, r in ranked]
        assert ratios[0] == 1 and ratios == sorted(ratios, reverse=True)


def test_the_doc_section_records_machine_and_load_but_no_date(result):
    before, after = machine(), machine()
    section = format_doc_section(result, "python -m rtpy bench furnace", before, after)
    assert section.startswith(GENERATED_BEGIN) and section.endswith(GENERATED_END)
    assert f"- CPU: {before['cpu']}, {before['cores']} cores" in section
    assert f"numpy {before['numpy']}" in section and "load average" in section
    assert "python -m rtpy bench furnace" in section and "| plane_point_light |" in section
    assert not re.search(r"\b(19|20)\d\d-\d\d-\d\d\b", section)


def test_replace_generated_keeps_what_is_written_by_hand():
    text = f"# Title\n\nprose\n\n{GENERATED_BEGIN}\nold table\n{GENERATED_END}\n\nmore prose\n"
    new = replace_generated(text, f"{GENERATED_BEGIN}\nnew table\n{GENERATED_END}")
    assert new == text.replace("old table", "new table")
    with pytest.raises(ValueError, match="no generated section"):
        replace_generated("# Title\n", "section")
    # A second section with markers of its own is left alone, and can be replaced alike.
    other = f"{new}<!-- b -->\nold rows\n<!-- e -->\n"
    assert replace_generated(other, "<!-- b -->\nrows\n<!-- e -->", "<!-- b -->", "<!-- e -->") == (
        f"{new}<!-- b -->\nrows\n<!-- e -->\n"
    )


def test_docs_bench_md_has_one_generated_section():
    if not DOC.exists():
        pytest.skip("docs/ is not part of this checkout")
    text = DOC.read_text()
    assert text.count(GENERATED_BEGIN) == 1 and text.count(GENERATED_END) == 1
    assert text.index(GENERATED_BEGIN) < text.index(GENERATED_END)


def test_docs_performance_md_shows_the_low_spp_table():
    """scripts/bench_low_spp.py --write-doc wrote its table: a row per scene, image size
    and worker count, each low-spp row with its share of the 32-spp row."""
    if not PERFORMANCE_DOC.exists():
        pytest.skip("docs/ is not part of this checkout")
    text = PERFORMANCE_DOC.read_text()
    begin = "<!-- generated by scripts/bench_low_spp.py: rerun it, do not edit -->"
    section = text[text.index(begin) : text.index("<!-- end of the low-spp section -->")]
    rows = [
        [cell.strip() for cell in line.strip("|").split("|")]
        for line in section.splitlines()
        if re.match(r"\| \w+ \| \d+x\d+ \|", line)
    ]
    assert {(image, spp, workers) for _, image, spp, workers, *_ in rows} >= {
        (size, spp, workers)
        for size, spp in (("256x144", "32"), ("1920x1080", "1"), ("3840x2160", "1"))
        for workers in ("1", "2")
    }
    assert all(re.fullmatch(r"\d+%", row[7]) for row in rows if row[2] == "1")


def test_docs_performance_md_shows_the_scene_size_table():
    """scripts/bench_scene_size.py --write-doc wrote its table: a row for each of 1k to
    1M triangles, with read (OBJ and PLY) and build times, and the ratios: once built
    and the first time from PLY against the goal, the first time from OBJ."""
    if not PERFORMANCE_DOC.exists():
        pytest.skip("docs/ is not part of this checkout")
    text = PERFORMANCE_DOC.read_text()
    begin = "<!-- generated by scripts/bench_scene_size.py: rerun it, do not edit -->"
    section = text[text.index(begin) : text.index("<!-- end of the scene-size section -->")]
    number = r" \| (\d+\.\d\d)"
    rows = re.findall(rf"^\| ([\d,]+){number * 3} \|", section, re.M)  # read OBJ, PLY, build
    sizes = [int(row[0].replace(",", "")) for row in rows]
    assert len(sizes) == 4
    assert all(a * 9 < b < a * 11 for a, b in zip(sizes, sizes[1:], strict=False))
    assert sizes[0] >= 1000 and sizes[-1] >= 1_000_000
    ply = r", \d+\.\d\dx the first time from PLY"
    for backend, first_ply in (("numpy", ply), ("scalar", "")):
        assert re.search(
            rf"^- {backend}, .* \d+\.\d\dx once built{first_ply} \(goal: at most 3x\); "
            r"\d+\.\d\dx the first time from OBJ;",
            section,
            re.M,
        )


def test_docs_performance_md_shows_the_speed_table_and_its_plot():
    """scripts/bench_speed.py --write-doc wrote the issue's ratios against their goals,
    the start-up steps and the plot."""
    if not PERFORMANCE_DOC.exists():
        pytest.skip("docs/ is not part of this checkout")
    text = PERFORMANCE_DOC.read_text()
    begin = "<!-- generated by scripts/bench_speed.py: rerun it, do not edit -->"
    section = text[text.index(begin) : text.index("<!-- end of the speed section -->")]
    ratios = dict(re.findall(r"^\| ([^|]+?) \| (\d+\.\d\dx|skipped) \| [\d.]+x \|$", section, re.M))
    assert set(ratios) == {
        "2 workers, cornell 128x128",
        "2 workers, cornell 256x256",
        "numpy / Mitsuba scalar_rgb",
        "scalar / course",
    }
    assert "2 workers" not in "".join(k for k, v in ratios.items() if v == "skipped")
    steps = re.findall(r"^\| (.+?) \| \d+\.\d{3} \|$", section, re.M)
    assert steps[0].startswith("interpreter") and steps[-1].startswith("whole")
    assert any("worker processes" in step for step in steps)
    plot = re.search(r"!\[[^]]*\]\((bench/speed\.png)\)", section)
    assert plot and (PERFORMANCE_DOC.parent / plot.group(1)).is_file()


def test_files_hold_every_level_and_non_finite_numbers_as_json_strings(result, tmp_path):
    csv_path, json_path = write_outputs(result, tmp_path / "out")
    with csv_path.open() as f:
        rows = list(csv.DictReader(f))
    assert list(rows[0]) == list(Level.__dataclass_fields__)
    assert len(rows) == len(result.levels)
    doc = json.loads(json_path.read_text())
    furnace = [lv for lv in doc["levels"] if lv["scene"] == "furnace"]
    assert all(lv["efficiency"] == "inf" for lv in furnace)  # exact: no error
    assert math.isfinite(doc["z_critical"]) and len(doc["fits"]) == len(result.fits)


def test_the_load_is_called_noisy_only_above_the_core_count():
    quiet = {"cpu": "x", "cores": 2, "system": "s", "python": "3", "numpy": "2"}
    calm = machine_lines(
        {**quiet, "load_average": (0.5, 0.4, 0.3)}, {**quiet, "load_average": (1.0, 0.5, 0.3)}
    )
    assert (
        calm[-1]
        == "- load average (1 / 5 / 15 min): 0.5 / 0.4 / 0.3 before the run, 1.0 / 0.5 / 0.3 after"
    )
    busy = machine_lines(
        {**quiet, "load_average": (0.5, 0.4, 0.3)}, {**quiet, "load_average": (3.0, 2.0, 1.0)}
    )
    assert busy[-1].endswith("above 2, so other work shared the cores and times are noisy")
    unknown = machine_lines({**quiet, "load_average": None}, {**quiet, "load_average": None})
    assert "unknown before the run, unknown after" in unknown[-1]


def test_direct_estimates_another_image_and_is_not_ranked(result):
    good = converged(result)

    def as_direct(x):
        return replace(x, integrator="direct") if x.integrator == "path-mis" else x

    direct = replace(good, fits=[as_direct(f) for f in good.fits])
    direct = replace(direct, levels=[as_direct(lv) for lv in good.levels])
    row = format_efficiency(direct).splitlines()[2]
    assert "path-brdf 1" in row and "direct" not in row


def as_direct(result: BenchResult) -> BenchResult:
    """The result with its path-mis series relabelled direct (measured against the
    depth-2 reference)."""

    def relabel(x):
        return replace(x, integrator="direct") if x.integrator == "path-mis" else x

    return replace(
        result, fits=[relabel(f) for f in result.fits], levels=[relabel(lv) for lv in result.levels]
    )


def test_plot_notes_name_the_exact_series_left_out_and_why(result):
    notes = plot_notes(result)
    assert notes[0].startswith("Error bars: relMSE ± 1 standard error")
    (left_out,) = [n for n in notes if n.startswith("Not drawn, exact")]
    for backend in ("numpy", "scalar"):
        for variant in ("path-brdf", "path-mis"):
            assert f"furnace/{variant} ({backend})" in left_out
    assert "plane_point_light" not in left_out
    assert not any("depth-2" in n or "--quick" in n for n in notes)


def test_plot_notes_mark_direct_and_quick(result):
    notes = plot_notes(as_direct(result), quick=True)
    assert any(n.startswith("Hollow markers") and "direct" in n and "depth-2" in n for n in notes)
    assert notes[-1].startswith("--quick:") and "mean nothing" in notes[-1]


def test_the_plot_draws_the_measured_standard_errors_and_its_notes(result):
    pytest.importorskip("matplotlib")
    import matplotlib

    matplotlib.use("Agg")
    fig = draw(as_direct(result), quick=True)
    noisy = [lv for lv in result.levels if lv.scene == "plane_point_light"]
    (time_axis, spp_axis) = fig.axes[:2]  # one row: the exact furnace is not drawn
    assert len(fig.axes) == 2 and "not meaningful" in time_axis.get_xlabel()
    bars = {}
    for container in spp_axis.containers:
        (segments,) = container.lines[2]  # the vertical bars
        for (x, low), (_, high) in segments.get_segments():
            bars[container.get_label(), x] = (low, high)
    for lv in noisy:
        label = f"{lv.integrator if lv.integrator != 'path-mis' else 'direct'} ({lv.backend})"
        label += ", depth-2 reference" if label.startswith("direct") else ""
        low, high = bars[label, lv.spp]
        se = lv.mse_se * lv.rel_mse / lv.mse  # relMSE is MSE over the reference's mean square
        assert se > 0 and math.isclose(low, lv.rel_mse - se) and math.isclose(high, lv.rel_mse + se)
    (note,) = fig.texts
    assert "furnace/path-brdf (numpy)" in note.get_text()
    assert "--quick" in note.get_text()
    styles = {c.get_label(): c.lines[0].get_linestyle() for c in spp_axis.containers}
    assert all((s == "-.") == ("depth-2" in label) for label, s in styles.items())


def test_samplers_get_their_own_series_and_efficiency_ratios():
    """One series per sampler; the gains table divides each sampler's efficiency by
    the independent sampler's, and a slope steeper than -1 is reported as faster than
    1/N, not as a problem."""
    run = run_bench(
        ["plane_point_light"],
        ("numpy",),
        ("direct",),
        (4, 16),
        samplers=("independent", "sobol"),
        repeats=2,
        width=8,
        log=lambda _: None,
    )
    assert [f.sampler for f in run.fits] == ["independent", "sobol"]
    gains = sampler_gains(run)
    last = {lv.sampler: lv for lv in run.levels if lv.spp == 16}
    ratio = last["sobol"].efficiency / last["independent"].efficiency
    assert gains == {("plane_point_light", "numpy", "direct"): {"sobol": ratio}}
    table = format_sampler_efficiency(run).splitlines()
    assert table[0].split()[-3:] == ["sobol", "/", "independent"]
    assert table[1].split()[-1] == f"{ratio:.2f}"
    assert format_sampler_efficiency(converged(run_without_samplers(run))) == ""
    steep = replace(run, fits=[replace(f, slope=-1.8, slope_se=0.01) for f in run.fits])
    assert [f.faster for f in steep.fits] == [False, True]
    assert [f.slope_ok for f in steep.fits] == [False, True]
    assert (
        "faster than 1/N (a stratifying sampler, not bias): plane_point_light/numpy/direct/sobol"
        in (findings(steep)[1])
    )
    assert len(steep.problems()) == 1 and "independent" not in steep.problems()[0]
    assert "(faster than 1/N)" in format_series(steep)


def run_without_samplers(run: BenchResult) -> BenchResult:
    keep = [f for f in run.fits if f.sampler == "independent"]
    return replace(run, fits=keep, levels=[lv for lv in run.levels if lv.sampler == "independent"])
