"""`rtpy bench`'s outputs: the tables it prints, bench.csv, bench.json and bench.png."""

from __future__ import annotations

import csv
import json
import math
import textwrap
from dataclasses import asdict
from pathlib import Path

import numpy as np

from ...io.image import WriteError, atomic_write
from ...sampler import SAMPLERS
from .convergence import (
    ALPHA,
    SLOPE_TOLERANCE,
    BenchResult,
    Fit,
    Level,
    series_key,
    series_name,
)
from .scenes import ALL_VARIANTS

TABLE_COLUMNS = (
    ("scene", "scene", "{}"),
    ("backend", "backend", "{}"),
    ("integrator", "integrator", "{}"),
    ("sampler", "sampler", "{}"),
    ("spp", "spp", "{}"),
    ("seconds", "s/render", "{:.3f}"),
    ("paths_per_second", "paths/s", "{:,.0f}"),
    ("peak_mb", "peak MB", "{:.0f}"),
    ("rmse", "RMSE", "{:.3g}"),
    ("rel_mse", "relMSE", "{:.3g}"),
    ("rel_bias", "bias (rel)", "{:+.2g}"),
    ("bias_z", "z", "{:+.1f}"),
    ("significant", "biased?", "{}"),
    ("efficiency", "1/(relMSE*s)", "{:.3g}"),
)


def _fmt(fmt: str, value) -> str:
    if isinstance(value, bool):
        return "YES" if value else "no"
    if isinstance(value, float) and not math.isfinite(value):
        return "inf" if value > 0 else ("-inf" if value < 0 else "nan")
    return fmt.format(value)


def table_rows(result: BenchResult) -> list[list[str]]:
    return [[_fmt(f, getattr(lv, key)) for key, _, f in TABLE_COLUMNS] for lv in result.levels]


def _layout(head: list[str], rows: list[list[str]], markdown: bool) -> str:
    if markdown:
        lines = ["| " + " | ".join(head) + " |", "|" + "---|" * len(head)]
        return "\n".join(lines + ["| " + " | ".join(r) + " |" for r in rows])
    widths = [max(len(h), *(len(r[i]) for r in rows)) for i, h in enumerate(head)]
    lines = ["  ".join(h.rjust(w) for h, w in zip(head, widths, strict=True))]
    lines += ["  ".join(c.rjust(w) for c, w in zip(r, widths, strict=True)) for r in rows]
    return "\n".join(lines)


def format_table(result: BenchResult, markdown: bool = False) -> str:
    """Every level of every series."""
    return _layout([h for _, h, _ in TABLE_COLUMNS], table_rows(result), markdown)


def _series(result: BenchResult, fit: Fit) -> list[Level]:
    """The levels of the series of `fit`, lowest spp first."""
    return [lv for lv in result.levels if series_key(lv) == series_key(fit)]


def _last_levels(result: BenchResult) -> list[Level]:
    """The highest-spp level of every series, in the order of result.fits."""
    return [_series(result, f)[-1] for f in result.fits]


def format_series(result: BenchResult, markdown: bool = False) -> str:
    """One row per series: its last (highest-spp) level, the fitted slope, and
    whether any level was significantly biased."""
    head = ["scene", "backend", "integrator", "sampler", "spp", "s/render", "paths/s", "peak MB"]
    head += ["relMSE", "1/(relMSE*s)", "slope", "biased?"]
    rows = []
    for f, last in zip(result.fits, _last_levels(result), strict=True):
        slope = "exact" if f.slope is None else f"{f.slope:+.2f} ± {f.slope_se:.2f}"
        slope += " (faster than 1/N)" if f.faster else ""
        biased = "YES" if any(lv.significant for lv in _series(result, f)) else "no"
        rows.append(
            [
                f.scene,
                f.backend,
                f.integrator,
                f.sampler,
                str(last.spp),
                f"{last.seconds:.2f}",
                f"{last.paths_per_second:,.0f}",
                f"{last.peak_mb:.0f}",
                _fmt("{:.2g}", last.rel_mse),
                _fmt("{:.3g}", last.efficiency),
                slope,
                biased,
            ]
        )
    note = (
        f"slope: of log MSE against log spp (unbiased: -1; a stratifying sampler may fall "
        f"faster than 1/N, below -1); biased?: |z| > "
        f"{result.z_critical:.2f} at some level (family-wise alpha {ALPHA:g})"
    )
    return _layout(head, rows, markdown) + "\n" + ("\n" if markdown else "") + note


def _json_value(v):
    if isinstance(v, float) and not math.isfinite(v):
        return None if math.isnan(v) else ("inf" if v > 0 else "-inf")
    return v


def write_outputs(result: BenchResult, out: Path) -> list[Path]:
    """bench.csv (one row per level) and bench.json (levels, fits, settings)."""
    try:
        out.mkdir(parents=True, exist_ok=True)
    except OSError as err:
        raise WriteError(out, err) from err
    csv_path, json_path = out / "bench.csv", out / "bench.json"
    fields = list(Level.__dataclass_fields__)

    def write_csv(tmp: Path) -> None:
        with tmp.open("w", newline="") as f:
            writer = csv.DictWriter(f, fieldnames=fields)
            writer.writeheader()
            for lv in result.levels:
                writer.writerow(asdict(lv))

    atomic_write(csv_path, write_csv)
    doc = {
        "settings": result.settings,
        "interrupted": result.interrupted,
        "z_critical": result.z_critical,
        "levels": [{k: _json_value(v) for k, v in asdict(lv).items()} for lv in result.levels],
        "fits": [
            {**{k: _json_value(v) for k, v in asdict(f).items()}, "slope_ok": f.slope_ok}
            for f in result.fits
        ],
    }
    atomic_write(json_path, lambda tmp: tmp.write_text(json.dumps(doc, indent=1)))
    return [csv_path, json_path]


def _other_reference(integrator: str) -> bool:
    """The variant estimates another image than full paths (direct: depth 2)."""
    return ALL_VARIANTS[integrator]["integrator"] == "direct"


def rel_mse_se(level: Level) -> float:
    """The standard error of a level's relMSE (relMSE is MSE times a constant)."""
    return level.rel_mse * level.mse_se / level.mse if level.mse > 0 else math.nan


def plot_notes(result: BenchResult, quick: bool = False) -> list[str]:
    """What the plot's reader must know: what the error bars are, which series and
    levels are not drawn and why, the variants measured against another reference,
    and, after --quick, that its timings mean nothing."""
    notes = ["Error bars: relMSE ± 1 standard error (from the spread of the squared errors)."]
    exact = [
        f"{f.scene}/{f.integrator}"
        + ("" if f.sampler == "independent" else f"/{f.sampler}")
        + f" ({f.backend})"
        for f in result.fits
        if all(lv.exact for lv in _series(result, f))
    ]
    if exact:
        notes.append(
            "Not drawn, exact (no error above rounding, nothing to put on a log axis): "
            + ", ".join(exact)
            + "."
        )
    below = [lv for lv in result.levels if not lv.exact and not lv.rel_mse > 0]
    if below:
        notes.append(
            f"Not drawn: {len(below)} level(s) whose MSE estimate is not above zero "
            "(within the reference's own noise)."
        )
    other = sorted({lv.integrator for lv in result.levels if _other_reference(lv.integrator)})
    if other:
        notes.append(
            f"Hollow markers, dash-dot lines: {', '.join(other)} estimates one bounce and "
            "is measured against the depth-2 reference, not the full paths' one; its "
            "error is not comparable with the other series'."
        )
    if quick:
        notes.append(
            "--quick: each render takes milliseconds, so the timings (left column) are "
            "overheads and noise and mean nothing; run without --quick to compare times."
        )
    return notes


def draw(result: BenchResult, quick: bool = False):
    """The bench figure (a matplotlib Figure), None when there is nothing to draw:
    relMSE with its error bars against time per render and against spp, log-log,
    one row per scene with drawn levels, and plot_notes() under it."""
    import matplotlib.pyplot as plt

    drawn = [lv for lv in result.levels if lv.rel_mse > 0 and not lv.exact]
    scenes = list(dict.fromkeys(lv.scene for lv in drawn))  # exact scenes: nothing to draw
    if not scenes:
        return None
    fig, axes = plt.subplots(
        len(scenes), 2, figsize=(10, 3.2 * len(scenes)), squeeze=False, constrained_layout=True
    )
    for row, scene in enumerate(scenes):
        series = {}
        for lv in drawn:
            if lv.scene == scene:
                series.setdefault((lv.backend, lv.integrator, lv.sampler), []).append(lv)
        for (backend, integrator, sampler), lvs in series.items():
            other = _other_reference(integrator)
            k = list(ALL_VARIANTS).index(integrator) * len(SAMPLERS) + list(SAMPLERS).index(sampler)
            color = f"C{k % 10}"
            named = integrator if sampler == "independent" else f"{integrator}, {sampler}"
            style = {
                "ls": "-." if other else ("-" if backend == "numpy" else "--"),
                "color": color,
                "marker": "o" if backend == "numpy" else "s",
                "mfc": "none" if other else color,
                "ms": 4,
                "capsize": 2,
                "label": f"{named} ({backend})" + (", depth-2 reference" if other else ""),
            }
            e = [lv.rel_mse for lv in lvs]
            se = [rel_mse_se(lv) for lv in lvs]
            axes[row, 0].errorbar([lv.seconds for lv in lvs], e, yerr=se, **style)
            axes[row, 1].errorbar([lv.spp for lv in lvs], e, yerr=se, **style)
        axes[row, 0].set_ylabel(f"{scene}\nrelative MSE")
        seconds = "seconds per render" + (" (--quick: not meaningful)" if quick else "")
        axes[row, 0].set_xlabel(seconds)
        axes[row, 1].set_xlabel("samples per pixel")
        s = np.array(sorted({lv.spp for lvs in series.values() for lv in lvs}), float)
        e0 = max(lvs[0].rel_mse for lvs in series.values())
        axes[row, 1].plot(s, e0 * s[0] / s, ":", color="gray", label="slope -1")
        axes[row, 1].legend(fontsize=7)
        for ax in axes[row]:
            ax.set_xscale("log")
            ax.set_yscale("log")
            ax.grid(True, which="both", alpha=0.3)
    notes = "\n".join(textwrap.fill(note, 150) for note in plot_notes(result, quick))
    fig.text(0.01, 0, notes, ha="left", va="top", fontsize=8)
    return fig


def plot(result: BenchResult, out: Path, quick: bool = False) -> Path | None:
    """bench.png, the figure of draw(); None when matplotlib is not installed or
    there is nothing to draw."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return None
    fig = draw(result, quick)
    if fig is None:
        return None

    def write(tmp: Path) -> None:  # the notes below the axes included
        fig.savefig(tmp, dpi=80, format="png", bbox_inches="tight")

    try:
        return atomic_write(out / "bench.png", write)
    finally:
        plt.close(fig)


# --------------------------------------------------------------------------- docs/bench.md

GENERATED_BEGIN = "<!-- generated by scripts/make_bench_doc.py: rerun it, do not edit -->"
GENERATED_END = "<!-- end of the generated section -->"


def machine_lines(before: dict, after: dict) -> list[str]:
    """The machine of a run (rtpy.cli.bench.machine.machine() before and after it)."""

    def load(m: dict) -> str:
        avg = m.get("load_average")
        return "unknown" if avg is None else " / ".join(f"{x:.1f}" for x in avg)

    busy = [m["load_average"][0] for m in (before, after) if m.get("load_average")]
    shared = (
        f": above {before['cores']}, so other work shared the cores and times are noisy"
        if busy and max(busy) > (before["cores"] or 1)
        else ""
    )
    return [
        f"- CPU: {before['cpu']}, {before['cores']} cores ({before['system']})",
        f"- Python {before['python']}, numpy {before['numpy']}",
        f"- load average (1 / 5 / 15 min): {load(before)} before the run, {load(after)} after"
        + shared,
    ]


def findings(result: BenchResult) -> list[str]:
    """What the run shows, computed from it: significant biases, slopes off -1
    (judged only where the slope's standard error is at most a quarter of the
    tolerance, as in the tests), and the numpy backend's speed against the
    scalar one."""
    biased = [
        f"{series_name(lv)} at {lv.spp} spp (z = {lv.bias_z:+.1f})"
        for lv in result.levels
        if lv.significant
    ]
    lines = [
        "- Bias: "
        + (
            "significant at " + ", ".join(biased) + f" (threshold {result.z_critical:.2f})."
            if biased
            else "no level is significantly biased."
        )
    ]
    fitted = [f for f in result.fits if f.slope is not None]
    judged = [f for f in fitted if f.slope_se <= SLOPE_TOLERANCE / 4]
    off = [f"{series_name(f)} ({f.slope:+.2f})" for f in judged if not f.slope_ok]
    faster = [f"{series_name(f)} ({f.slope:+.2f})" for f in judged if f.faster]
    loose = [series_name(f) for f in fitted if f not in judged]
    tolerance = f"{SLOPE_TOLERANCE:g}"
    verdict = (
        f"off -1 by more than {tolerance}: " + ", ".join(off)
        if off
        else f"all of them are -1 within {tolerance}"
    )
    text = (
        f"{len(judged)} of {len(fitted)} series are measured to "
        f"± {SLOPE_TOLERANCE / 4:g} or better; {verdict}"
        if judged
        else f"no slope is measured to ± {SLOPE_TOLERANCE / 4:g} or better"
    )
    if faster:
        text += f"; faster than 1/N (a stratifying sampler, not bias): {', '.join(faster)}"
    if loose:
        text += f". Too few levels or too noisy to judge: {', '.join(loose)}"
    lines.append(f"- Slopes: {text}.")
    speed: dict[tuple[str, str, str], list[float]] = {}
    for lv in result.levels:
        key = (lv.scene, f"{lv.integrator} {lv.sampler}", lv.backend)
        speed.setdefault(key, []).append(lv.paths_per_second)
    ratios = [
        np.mean(speed[scene, integrator, "numpy"]) / np.mean(speed[scene, integrator, "scalar"])
        for scene, integrator, backend in speed
        if backend == "numpy" and (scene, integrator, "scalar") in speed
    ]
    if ratios:
        lines.append(
            f"- Speed: the numpy backend traces {min(ratios):.0f}-{max(ratios):.0f} times the "
            "scalar backend's paths/s (mean over the levels of each series)."
        )
    return lines


def format_efficiency(result: BenchResult) -> str:
    """A markdown table: per scene and backend, the path-tracing variants from the
    most to the least efficient (1/(relMSE*s) at the highest spp of each series,
    relative to the best). "direct" estimates another image (one bounce) and is
    not ranked; scenes without error (exact) are left out."""
    best: dict[tuple[str, str], list[tuple[float, str]]] = {}
    for f, last in zip(result.fits, _last_levels(result), strict=True):
        same_image = ALL_VARIANTS[f.integrator]["integrator"] == "path"
        named = f.integrator if f.sampler == "independent" else f"{f.integrator}+{f.sampler}"
        if same_image and f.slope is not None and math.isfinite(last.efficiency):
            best.setdefault((f.scene, f.backend), []).append((last.efficiency, named))
    backends = list(dict.fromkeys(backend for _, backend in best))
    scenes = list(dict.fromkeys(scene for scene, _ in best))
    rows = []
    for scene in scenes:
        row = [scene]
        for backend in backends:
            ranked = sorted(best.get((scene, backend), []), reverse=True)
            row.append(", ".join(f"{v} {e / ranked[0][0]:.2g}" for e, v in ranked) or "-")
        rows.append(row)
    head = ["scene", *(f"path tracing, {b}: efficiency relative to the best" for b in backends)]
    return _layout(head, rows, markdown=True)


def sampler_gains(result: BenchResult) -> dict[tuple[str, str, str], dict[str, float]]:
    """Per (scene, backend, variant) measured with the independent sampler and another:
    each sampler's efficiency 1/(relMSE*s) at its series' highest spp divided by the
    independent sampler's (above 1: the sampler buys the same error in less time)."""
    last = {series_key(f): lv for f, lv in zip(result.fits, _last_levels(result), strict=True)}
    gains: dict[tuple[str, str, str], dict[str, float]] = {}
    for (scene, backend, variant, sampler), lv in last.items():
        base = last.get((scene, backend, variant, "independent"))
        if sampler == "independent" or base is None:
            continue
        finite = math.isfinite(lv.efficiency) and math.isfinite(base.efficiency)
        ratio = lv.efficiency / base.efficiency if finite else math.nan
        gains.setdefault((scene, backend, variant), {})[sampler] = ratio
    return gains


def format_sampler_efficiency(result: BenchResult, markdown: bool = False) -> str:
    """A table of sampler_gains(), one row per series measured with several samplers
    ("" when there is none)."""
    gains = sampler_gains(result)
    samplers = [s for s in SAMPLERS if any(s in g for g in gains.values())]
    if not samplers:
        return ""
    head = ["scene", "backend", "integrator", *(f"{s} / independent" for s in samplers)]
    rows = [
        [*key, *(_fmt("{:.2f}", g[s]) if s in g else "-" for s in samplers)]
        for key, g in gains.items()
    ]
    note = "efficiency 1/(relMSE*s) at the highest spp, relative to the independent sampler's"
    return _layout(head, rows, markdown) + "\n" + ("\n" if markdown else "") + note


def format_doc_section(result: BenchResult, command: str, before: dict, after: dict) -> str:
    """The generated section of docs/bench.md: the command, the machine and its
    load, the table of series, the plot and the findings. No dates: the git
    history says when."""
    settings = result.settings
    parts = [
        GENERATED_BEGIN,
        "",
        "```sh",
        command,
        "```",
        "",
        f"{settings.get('width')} px wide, {settings.get('repeats')} repeats per level; "
        "one row per series at its highest spp (every level is in "
        "[`bench/bench.csv`](bench/bench.csv)). Measured on:",
        "",
        *machine_lines(before, after),
        "",
        format_series(result, markdown=True),
        "",
        "![relative MSE against time and against spp](bench/bench.png)",
        "",
        *findings(result),
        "",
        format_efficiency(result),
        "",
        format_sampler_efficiency(result, markdown=True),
        "",
        GENERATED_END,
    ]
    return "\n".join(parts)


def replace_generated(
    text: str, section: str, begin: str = GENERATED_BEGIN, end: str = GENERATED_END
) -> str:
    """text with its generated section (from the line `begin` to the line `end`,
    which `section` starts and ends with) replaced."""
    first, last = text.find(begin), text.find(end)
    if first < 0 or last < first:
        raise ValueError("the document has no generated section to replace")
    return text[:first] + section + text[last + len(end) :]
