"""rtpy.bench.report: the printed tables, the files, and the generated section of
docs/bench.md."""

from __future__ import annotations

import csv
import json
import math
import re
from dataclasses import replace
from pathlib import Path

import pytest

from rtpy.bench.convergence import BenchResult, Level
from rtpy.bench.machine import machine
from rtpy.bench.report import (
    GENERATED_BEGIN,
    GENERATED_END,
    findings,
    format_doc_section,
    format_series,
    format_table,
    machine_lines,
    replace_generated,
    write_outputs,
)
from rtpy.bench.run import run_bench

DOC = Path(__file__).resolve().parents[2] / "docs" / "bench.md"


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
    assert table[0].split()[:4] == ["scene", "backend", "integrator", "spp"]
    series = format_series(result, markdown=True).splitlines()
    rows = [line for line in series if line.startswith("| ") and "---" not in line]
    assert len(rows) == 1 + len(result.fits) == 1 + 8
    assert all(row.count("|") == 12 for row in rows)  # 11 columns
    furnace = [row for row in rows if row.startswith("| furnace ")]
    assert furnace and all("| exact |" in row for row in furnace)
    assert series[-1].startswith("slope: of log MSE against log spp")


def converged(result: BenchResult) -> BenchResult:
    """result with every fitted slope -1 (a run this small cannot fit slopes)."""
    fits = [f if f.slope is None else replace(f, slope=-1.0, slope_se=0.01) for f in result.fits]
    return replace(result, fits=fits)


def test_findings_give_the_verdict_the_speed_ratio_and_the_best_integrator(result):
    lines = findings(converged(result))
    assert lines[0].startswith("- Convergence: no series has a significant bias")
    (speed,) = [line for line in lines if line.startswith("- Speed:")]
    assert re.search(r"traces \d+-\d+ times the scalar backend's paths/s", speed)
    best = [line for line in lines if line.startswith("- Most efficient on")]
    # the furnace has no error: no integrator is more efficient than another
    assert {line.split(" (")[0] for line in best} == {"- Most efficient on plane_point_light"}
    assert len(best) == 2  # one per backend


def test_findings_report_a_biased_series_and_a_wrong_slope(result):
    good = converged(result)
    level = replace(good.levels[-1], significant=True)
    biased = replace(good, levels=[*good.levels[:-1], level])
    assert findings(biased)[0] == f"- Convergence: problems: {biased.problems()[0]}."
    assert biased.problems()[0].startswith(f"{level.scene}/{level.backend}/")
    flat = replace(good, fits=[replace(good.fits[-1], slope=-0.5), *good.fits[:-1]])
    assert "slope -0.500" in findings(flat)[0]


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


def test_docs_bench_md_has_one_generated_section():
    if not DOC.exists():
        pytest.skip("docs/ is not part of this checkout")
    text = DOC.read_text()
    assert text.count(GENERATED_BEGIN) == 1 and text.count(GENERATED_END) == 1
    assert text.index(GENERATED_BEGIN) < text.index(GENERATED_END)


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
