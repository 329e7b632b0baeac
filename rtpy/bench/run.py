"""`python -m rtpy bench`: speed against error, measured against references
that are known to be right (rtpy.testing.reference, rtpy.testing.analytic_scenes).

For every scene, backend and integrator variant, each spp level is rendered
`repeats` times with independent seeds. A level records: the wall time of one
render, paths/s, the peak resident memory of the render, and against the
reference R (over its mask, all channels):

- MSE = mean (I - R)^2 - mean var(R)   (the reference's own noise subtracted),
  RMSE = sqrt(MSE), relMSE = MSE / mean R^2 (independent of the scene's units);
- bias = mean (I - R), given relative to mean R, with its standard error from
  the spread of each pixel's values over the repeats (pixels are independent:
  SE^2 = sum_p s_p^2 / (repeats P^2) + the reference's variance); it is
  significant when |bias / SE| exceeds the two-sided normal quantile at a
  family-wise level ALPHA, Bonferroni-corrected over every level of the run,
  and is more than BIAS_FLOOR of mean R (rays start 1e-9 off surfaces);
- efficiency = 1 / (relMSE * seconds per render).

For each series it fits log MSE = a + slope log spp by weighted least squares,
each level weighted by 1 / var(log MSE), var(log MSE) ~ (SE(MSE) / MSE)^2 with
SE(MSE) from the spread of the per-pixel squared errors; the slope's standard
error is sqrt(1 / sum w (x - mean_w x)^2). An unbiased estimator has
E[MSE] = sigma^2 / spp exactly (independent samples), so slope = -1; a bias b
adds b^2, which flattens the slope as spp grows.
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import resource
import sys
import time
from dataclasses import asdict, dataclass, field
from pathlib import Path
from statistics import NormalDist

import numpy as np

from ..camera import Camera
from ..scene import Scene
from ..testing.analytic_scenes import ANALYTIC_SCENES, analytic_scene
from ..testing.reference import DEFAULT_REFERENCE_SPP, Reference, analytic_reference, get_reference

# Integrator variants: render settings on top of the scene's own.
VARIANTS: dict[str, dict] = {
    "path-brdf": {"integrator": "path", "nee": False},  # BRDF sampling only
    "path-nee": {"integrator": "path", "nee": True, "mis": False},  # light sampling only
    "path-mis": {"integrator": "path", "nee": True, "mis": True},  # both, power heuristic
    "direct": {"integrator": "direct", "nee": True, "mis": True},  # one bounce (depth 2)
}
BACKENDS = ("numpy", "scalar")
ALPHA = 1e-3  # family-wise false-alarm rate of the bias tests of one run
SLOPE_TOLERANCE = 0.15  # |slope + 1| allowed for an unbiased estimator
# Rays leave surfaces 1e-9 (relative) off them, so even exact estimators are off by
# about that much: a bias below BIAS_FLOOR (relative) is never flagged, and an RMSE
# below ROUNDING (relative) counts as zero error (no slope to fit).
BIAS_FLOOR = 1e-6
ROUNDING = 1e-7
DEFAULT_SPP = (1, 4, 16, 64)
MAX_BUDGET_SPP = 1 << 16
QUICK = {"width": 16, "spp": (1, 4, 16), "repeats": 2}


# --------------------------------------------------------------------------- scenes


@dataclass
class BenchScene:
    """A scene to measure: what to render and how to get its reference."""

    name: str
    scene: Scene
    camera: Camera
    max_depth: int
    russian_roulette: int
    reference_for: object  # callable(max_depth) -> Reference


def load_bench_scene(
    name: str,
    width: int | None,
    cache: Path | None = None,
    reference_spp: int = DEFAULT_REFERENCE_SPP,
    log=print,
) -> BenchScene:
    """An analytic scene by name, or a scene file / bundled scene (rendered reference)."""
    if name in ANALYTIC_SCENES:
        a = analytic_scene(name)
        camera = a.camera.with_width(width) if width else a.camera
        return BenchScene(
            name,
            a.scene,
            camera,
            a.settings.max_depth,
            a.settings.russian_roulette,
            lambda depth: analytic_reference(a, camera, depth),
        )
    from .. import load_scene
    from ..io.bundled import resolve_scene

    path = resolve_scene(name)
    scene = load_scene(path)
    camera = scene.camera.with_width(width) if width else scene.camera
    settings = scene.settings

    def reference_for(depth: int) -> Reference:
        return get_reference(path, camera.width, depth, reference_spp, cache, log=log)

    return BenchScene(
        path.stem, scene, camera, settings.max_depth, settings.russian_roulette, reference_for
    )


def effective_depth(variant: str, max_depth: int) -> int:
    """The max_depth whose image the variant estimates ("direct" is depth 2)."""
    return 2 if VARIANTS[variant]["integrator"] == "direct" else max_depth


# --------------------------------------------------------------------------- measuring


def _reset_peak_rss() -> bool:
    """Reset the kernel's peak-RSS counter of this process (Linux); False if not possible."""
    try:
        with open("/proc/self/clear_refs", "w") as f:
            f.write("5")
        return True
    except OSError:
        return False


def _peak_rss_mb(reset_ok: bool) -> float:
    if reset_ok:
        try:
            with open("/proc/self/status") as f:
                for line in f:
                    if line.startswith("VmHWM:"):
                        return int(line.split()[1]) / 1024.0
        except OSError:
            pass
    # Fallback: the process's peak so far (kilobytes on Linux).
    return resource.getrusage(resource.RUSAGE_SELF).ru_maxrss / 1024.0


def render_once(bs: BenchScene, backend: str, variant: str, spp: int, seed: int, workers: int):
    """(linear image, seconds, peak RSS in MB) of one render."""
    from .. import render

    reset_ok = _reset_peak_rss()
    start = time.perf_counter()
    image = render(
        bs.scene,
        camera=bs.camera,
        backend=backend,
        spp=spp,
        seed=seed,
        max_depth=bs.max_depth,
        russian_roulette=bs.russian_roulette,
        workers=workers,
        **VARIANTS[variant],
    )
    seconds = time.perf_counter() - start
    if image.interrupted:  # Ctrl-C inside the render: a partial image is no measurement
        raise KeyboardInterrupt
    return image.linear, seconds, _peak_rss_mb(reset_ok)


def error_stats(images: np.ndarray, ref: Reference) -> dict[str, float]:
    """Errors of `images` (repeats, H, W, 3), independent renders, against ref:
    mse and its standard error mse_se, rel_mse, bias and its standard error
    bias_se, rel_bias (the Level fields of the same names)."""
    e = images[:, ref.mask, :] - ref.image[ref.mask]  # (repeats, P, 3)
    var_ref = ref.variance[ref.mask]  # (P, 3)
    sq = (e * e - var_ref).mean(axis=2).ravel()  # per render and pixel
    n = sq.size
    mse = float(sq.mean())
    mse_se = float(sq.std(ddof=1) / math.sqrt(n)) if n > 1 else math.inf
    ref_sq = float((ref.image[ref.mask] ** 2).mean())
    per_pixel = e.mean(axis=2)  # (repeats, P)
    repeats, pixels = per_pixel.shape
    bias = float(per_pixel.mean())
    if repeats > 1:
        s2 = per_pixel.var(axis=0, ddof=1)
        bias_var = s2.sum() / (repeats * pixels**2)
    else:
        bias_var = math.inf
    bias_var += float(var_ref.mean(axis=1).sum()) / pixels**2
    ref_mean = float(ref.image[ref.mask].mean())
    return {
        "mse": mse,
        "mse_se": mse_se,
        "rel_mse": mse / ref_sq if ref_sq > 0 else math.nan,
        "bias": bias,
        "bias_se": math.sqrt(bias_var),
        "rel_bias": bias / ref_mean if ref_mean != 0 else math.nan,
    }


def z_score(bias: float, se: float, scale: float) -> float:
    """bias / se; for a noise-free estimate (se = 0), 0 if the bias is rounding
    (below 1e-12 of the reference's scale), else infinite."""
    if se > 0:
        return bias / se
    return 0.0 if abs(bias) <= 1e-12 * max(scale, 1e-300) else math.copysign(math.inf, bias)


def z_critical(n_tests: int, alpha: float = ALPHA) -> float:
    """Two-sided normal quantile at family-wise level alpha over n_tests (Bonferroni)."""
    return NormalDist().inv_cdf(1.0 - alpha / (2.0 * max(n_tests, 1)))


@dataclass
class Level:
    """One spp level of one (scene, backend, integrator) series."""

    scene: str
    backend: str
    integrator: str
    spp: int
    repeats: int
    width: int
    height: int
    seconds: float  # per render (mean over the repeats)
    paths_per_second: float
    peak_mb: float
    rmse: float
    mse: float
    mse_se: float
    rel_mse: float
    bias: float
    bias_se: float
    rel_bias: float
    bias_z: float
    exact: bool = False  # RMSE below ROUNDING of the reference's scale: no error
    significant: bool = False
    efficiency: float = math.nan
    reference: str = ""


@dataclass
class Fit:
    """The fitted slope of log MSE against log spp for one series."""

    scene: str
    backend: str
    integrator: str
    slope: float | None
    slope_se: float | None
    levels: int
    note: str = ""

    @property
    def slope_ok(self) -> bool:
        return self.slope is not None and abs(self.slope + 1.0) < SLOPE_TOLERANCE


def fit_slope(spps, mses, mse_ses, zero: float = 0.0) -> tuple[float | None, float | None]:
    """Weighted least-squares slope of log MSE on log spp and its standard error;
    (None, None) with fewer than 2 levels of MSE above `zero`."""
    pts = [
        (math.log(s), math.log(m), (se / m) ** 2)
        for s, m, se in zip(spps, mses, mse_ses, strict=True)
        if m > zero and math.isfinite(se)
    ]
    if len({p[0] for p in pts}) < 2:
        return None, None
    x = np.array([p[0] for p in pts])
    y = np.array([p[1] for p in pts])
    w = 1.0 / np.maximum(np.array([p[2] for p in pts]), 1e-300)
    xm = (w * x).sum() / w.sum()
    ym = (w * y).sum() / w.sum()
    sxx = (w * (x - xm) ** 2).sum()
    slope = float((w * (x - xm) * (y - ym)).sum() / sxx)
    return slope, float(math.sqrt(1.0 / sxx))


@dataclass
class BenchResult:
    levels: list[Level] = field(default_factory=list)
    fits: list[Fit] = field(default_factory=list)
    z_critical: float = math.nan
    settings: dict = field(default_factory=dict)
    interrupted: bool = False  # stopped by Ctrl-C: holds the levels finished before

    def finish(self) -> None:
        """Decide significance (Bonferroni over all levels) and efficiency."""
        self.z_critical = z_critical(len(self.levels))
        for lv in self.levels:
            lv.significant = bool(
                abs(lv.bias_z) > self.z_critical and not abs(lv.rel_bias) <= BIAS_FLOOR
            )
            denom = lv.rel_mse * lv.seconds
            lv.efficiency = 1.0 / denom if denom > 0 and not lv.exact else math.inf

    def problems(self, variants=None) -> list[str]:
        """Series that fail the unbiasedness check: a significant bias at any level,
        or a fitted slope outside -1 +- SLOPE_TOLERANCE (series with zero error,
        which have no slope, pass on their bias alone)."""
        out = []
        for lv in self.levels:
            if (variants is None or lv.integrator in variants) and lv.significant:
                out.append(
                    f"{lv.scene}/{lv.backend}/{lv.integrator} spp {lv.spp}: bias "
                    f"{lv.bias:+.3g} (z = {lv.bias_z:.1f} > {self.z_critical:.2f})"
                )
        for f in self.fits:
            if (variants is None or f.integrator in variants) and f.slope is not None:
                if not f.slope_ok:
                    out.append(
                        f"{f.scene}/{f.backend}/{f.integrator}: slope {f.slope:.3f} "
                        f"+- {f.slope_se:.3f} outside -1 +- {SLOPE_TOLERANCE}"
                    )
        return out


def run_series(
    bs: BenchScene,
    backend: str,
    variant: str,
    spps,
    budget: float | None,
    repeats: int,
    workers: int,
    ref: Reference,
    log=print,
    seed: int = 1,
    levels: list[Level] | None = None,
) -> list[Level]:
    """Render the levels of one series, appended to `levels` as they are done (so
    a Ctrl-C keeps them); with a budget, spp doubles from 1 while the next level is
    predicted to fit in what is left."""
    levels = [] if levels is None else levels
    spent = 0.0
    k = 0
    spp_iter = iter(spps) if budget is None else None
    spp = 1
    while True:
        if spp_iter is not None:
            spp = next(spp_iter, None)
            if spp is None:
                break
        images, times, peaks = [], [], []
        for r in range(repeats):
            # independent across levels and repeats
            img, sec, peak = render_once(bs, backend, variant, spp, seed + 1000 * k + r, workers)
            images.append(img)
            times.append(sec)
            peaks.append(peak)
        spent += sum(times)
        st = error_stats(np.stack(images), ref)
        seconds = float(np.mean(times))
        scale = float(np.abs(ref.image[ref.mask]).mean())
        lv = Level(
            scene=bs.name,
            backend=backend,
            integrator=variant,
            spp=spp,
            repeats=repeats,
            width=bs.camera.width,
            height=bs.camera.height,
            seconds=seconds,
            paths_per_second=bs.camera.width * bs.camera.height * spp / seconds,
            peak_mb=float(max(peaks)),
            rmse=math.sqrt(max(st["mse"], 0.0)),
            **st,
            bias_z=z_score(st["bias"], st["bias_se"], scale),
            exact=bool(st["mse"] <= (ROUNDING * scale) ** 2),
            reference=ref.source,
        )
        levels.append(lv)
        log(
            f"  {bs.name} {backend} {variant} spp {spp}: {seconds:.3f} s/render, "
            f"relMSE {lv.rel_mse:.3g}"
        )
        k += 1
        if budget is not None:
            # The next level costs about twice this one.
            if spent + 2.0 * sum(times) > budget or spp * 2 > MAX_BUDGET_SPP:
                if k >= 2:
                    break
            spp *= 2
    return levels


def run_bench(
    scenes: list[str],
    backends=("numpy",),
    variants=tuple(VARIANTS),
    spps=DEFAULT_SPP,
    *,
    budget: float | None = None,
    repeats: int = 4,
    width: int | None = 64,
    workers: int = 1,
    cache: Path | None = None,
    reference_spp: int = DEFAULT_REFERENCE_SPP,
    log=print,
    seed: int = 1,
) -> BenchResult:
    result = BenchResult(
        settings={
            "scenes": list(scenes),
            "backends": list(backends),
            "integrators": list(variants),
            "spp": None if budget is not None else list(spps),
            "budget_seconds": budget,
            "repeats": repeats,
            "width": width,
            "workers": workers,
            "seed": seed,
            "alpha": ALPHA,
            "slope_tolerance": SLOPE_TOLERANCE,
            "date": time.strftime("%Y-%m-%d %H:%M:%S"),
        }
    )

    def fit(bs: BenchScene, backend: str, variant: str, levels: list[Level], ref) -> None:
        result.levels.extend(levels)
        scale = float(np.abs(ref.image[ref.mask]).mean())
        slope, se = fit_slope(
            [lv.spp for lv in levels],
            [lv.mse for lv in levels],
            [lv.mse_se for lv in levels],
            zero=(ROUNDING * scale) ** 2,
        )
        note = "" if slope is not None else "no slope: error is zero (exact) or one level"
        result.fits.append(Fit(bs.name, backend, variant, slope, se, len(levels), note))

    current = None
    try:
        for name in scenes:
            bs = load_bench_scene(name, width, cache, reference_spp, log)
            refs: dict[int, Reference] = {}
            for backend in backends:
                for variant in variants:
                    depth = effective_depth(variant, bs.max_depth)
                    if depth not in refs:
                        refs[depth] = bs.reference_for(depth)
                    current = (bs, backend, variant, [], refs[depth])
                    run_series(
                        bs,
                        backend,
                        variant,
                        spps,
                        budget,
                        repeats,
                        workers,
                        refs[depth],
                        log,
                        seed,
                        levels=current[3],
                    )
                    fit(*current)
                    current = None
    except KeyboardInterrupt:
        result.interrupted = True
        if current is not None and current[3]:
            fit(*current)  # the levels of the series that was running
    result.finish()
    return result


# --------------------------------------------------------------------------- output

TABLE_COLUMNS = (
    ("scene", "scene", "{}"),
    ("backend", "backend", "{}"),
    ("integrator", "integrator", "{}"),
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


def format_series(result: BenchResult, markdown: bool = False) -> str:
    """One row per series: its last (highest-spp) level, the fitted slope, and
    whether any level was significantly biased."""
    head = ["scene", "backend", "integrator", "spp", "s/render", "paths/s", "peak MB"]
    head += ["relMSE", "1/(relMSE*s)", "slope", "biased?"]
    rows = []
    for f in result.fits:
        mine = [
            lv
            for lv in result.levels
            if (lv.scene, lv.backend, lv.integrator) == (f.scene, f.backend, f.integrator)
        ]
        last = mine[-1]
        slope = "exact" if f.slope is None else f"{f.slope:+.2f} ± {f.slope_se:.2f}"
        biased = "YES" if any(lv.significant for lv in mine) else "no"
        rows.append(
            [
                f.scene,
                f.backend,
                f.integrator,
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
        f"slope: of log MSE against log spp (unbiased: -1); biased?: |z| > "
        f"{result.z_critical:.2f} at some level (family-wise alpha {ALPHA:g})"
    )
    return _layout(head, rows, markdown) + "\n" + ("\n" if markdown else "") + note


def _json_value(v):
    if isinstance(v, float) and not math.isfinite(v):
        return None if math.isnan(v) else ("inf" if v > 0 else "-inf")
    return v


def write_outputs(result: BenchResult, out: Path) -> list[Path]:
    """bench.csv (one row per level) and bench.json (levels, fits, settings)."""
    out.mkdir(parents=True, exist_ok=True)
    csv_path, json_path = out / "bench.csv", out / "bench.json"
    fields = list(Level.__dataclass_fields__)
    tmp = csv_path.with_suffix(".csv.tmp")
    with tmp.open("w", newline="") as f:
        writer = csv.DictWriter(f, fieldnames=fields)
        writer.writeheader()
        for lv in result.levels:
            writer.writerow(asdict(lv))
    tmp.replace(csv_path)
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
    tmp = json_path.with_suffix(".json.tmp")
    tmp.write_text(json.dumps(doc, indent=1))
    tmp.replace(json_path)
    return [csv_path, json_path]


def plot(result: BenchResult, out: Path) -> Path | None:
    """bench.png: relMSE against time per render and against spp, log-log, one row
    per scene (levels with no error left out); None when matplotlib is not
    installed or there is nothing to draw."""
    try:
        import matplotlib

        matplotlib.use("Agg")
        import matplotlib.pyplot as plt
    except ImportError:
        return None
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
                series.setdefault((lv.backend, lv.integrator), []).append(lv)
        for (backend, integrator), lvs in series.items():
            label = f"{integrator} ({backend})"
            style = {
                "ls": "-" if backend == "numpy" else "--",
                "color": f"C{list(VARIANTS).index(integrator) % 10}",
                "marker": "o" if backend == "numpy" else "s",
                "ms": 3,
                "label": label,
            }
            t = [lv.seconds for lv in lvs]
            e = [lv.rel_mse for lv in lvs]
            axes[row, 0].loglog(t, e, **style)
            axes[row, 1].loglog([lv.spp for lv in lvs], e, **style)
        axes[row, 0].set_ylabel(f"{scene}\nrelative MSE")
        axes[row, 0].set_xlabel("seconds per render")
        axes[row, 1].set_xlabel("samples per pixel")
        if series:
            s = np.array(sorted({lv.spp for lvs in series.values() for lv in lvs}), float)
            e0 = max(lvs[0].rel_mse for lvs in series.values())
            axes[row, 1].loglog(s, e0 * s[0] / s, ":", color="gray", label="slope -1")
            axes[row, 1].legend(fontsize=7)
        for ax in axes[row]:
            ax.grid(True, which="both", alpha=0.3)
    path = out / "bench.png"
    tmp = out / ".bench.png.tmp"
    fig.savefig(tmp, dpi=80, format="png")
    plt.close(fig)
    tmp.replace(path)
    return path


# --------------------------------------------------------------------------- command


def add_parser(sub) -> argparse.ArgumentParser:
    b = sub.add_parser(
        "bench",
        help="measure speed against error",
        description="Render scenes with each backend and integrator at increasing spp and "
        "measure time, memory and error against a reference that is known to be right "
        f"(analytic scenes: {', '.join(ANALYTIC_SCENES)}; other scenes: a cached "
        "high-spp render).",
    )
    b.add_argument(
        "scenes",
        nargs="*",
        metavar="SCENE",
        help="analytic scene, bundled scene or .toml path (default: every analytic scene)",
    )
    b.add_argument("--backends", default=None, help="comma-separated: numpy,scalar (default numpy)")
    b.add_argument(
        "--integrators",
        default=None,
        help=f"comma-separated variants: {','.join(VARIANTS)} (default all)",
    )
    g = b.add_mutually_exclusive_group()
    g.add_argument("--budget", type=float, metavar="SECONDS", help="seconds per series")
    g.add_argument("--spp", default=None, help="comma-separated spp levels (default 1,4,16,64)")
    b.add_argument("--out", default="rtpy-bench", metavar="DIR", help="output folder")
    b.add_argument("--width", type=int, default=None, help="image width (default 64; quick 16)")
    b.add_argument("--repeats", type=int, default=None, help="renders per level (>= 2; default 4)")
    b.add_argument("--workers", type=int, default=1, help="processes per render (default 1)")
    b.add_argument(
        "--reference-spp",
        type=int,
        default=DEFAULT_REFERENCE_SPP,
        help=f"spp of rendered references (default {DEFAULT_REFERENCE_SPP})",
    )
    b.add_argument(
        "--cache", default=None, metavar="DIR", help="reference cache (default ~/.cache/rtpy)"
    )
    b.add_argument(
        "--quick", action="store_true", help="small and fast: width 16, spp 1,4,16, 2 repeats"
    )
    return b


class BenchUsageError(Exception):
    pass


def _split(text: str | None, allowed, what: str) -> list[str] | None:
    if text is None:
        return None
    items = [t.strip() for t in text.split(",") if t.strip()]
    bad = [t for t in items if t not in allowed]
    if bad or not items:
        raise BenchUsageError(f"--{what}: expected a comma-separated list of {', '.join(allowed)}")
    return items


def _spp_list(text: str) -> list[int]:
    try:
        values = [int(t) for t in text.split(",") if t.strip()]
    except ValueError:
        raise BenchUsageError(
            f"--spp: expected whole numbers such as 1,4,16,64; got {text!r}"
        ) from None
    from ..io.scene_file import MAX_SPP

    if len(values) < 1 or any(not 1 <= v <= MAX_SPP for v in values):
        raise BenchUsageError(f"--spp: expected numbers from 1 to {MAX_SPP}; got {text!r}")
    return values


def command_bench(args: argparse.Namespace) -> int:
    from ..io.scene_file import SceneError

    def log(msg: str) -> None:
        print(msg, file=sys.stderr)

    try:
        backends = _split(args.backends, BACKENDS, "backends") or ["numpy"]
        variants = _split(args.integrators, tuple(VARIANTS), "integrators") or list(VARIANTS)
        width = args.width or (QUICK["width"] if args.quick else 64)
        repeats = args.repeats or (QUICK["repeats"] if args.quick else 4)
        if repeats < 2:
            raise BenchUsageError("--repeats: at least 2 (the bias test needs the spread)")
        from ..io.scene_file import MAX_WIDTH

        if not 1 <= width <= MAX_WIDTH:
            raise BenchUsageError(f"--width: expected a whole number from 1 to {MAX_WIDTH}")
        if args.workers < 1 or args.reference_spp < 1:
            raise BenchUsageError("--workers and --reference-spp must be >= 1")
        if args.budget is not None and not args.budget > 0:
            raise BenchUsageError("--budget: expected seconds > 0")
        spps = _spp_list(args.spp) if args.spp else (QUICK["spp"] if args.quick else DEFAULT_SPP)
        scenes = args.scenes or list(ANALYTIC_SCENES)
        for name in scenes:
            if name not in ANALYTIC_SCENES:
                from ..io.bundled import resolve_scene

                resolve_scene(name)
        out = Path(args.out)
        if out.exists() and not out.is_dir():
            raise BenchUsageError(f"--out {out}: not a folder")
    except (BenchUsageError, SceneError) as err:
        print(f"rtpy: error: {err}", file=sys.stderr)
        return 2
    reference_spp = min(args.reference_spp, 256) if args.quick else args.reference_spp
    try:
        result = run_bench(
            scenes,
            backends,
            variants,
            spps,
            budget=args.budget,
            repeats=repeats,
            width=width,
            workers=args.workers,
            cache=Path(args.cache) if args.cache else None,
            reference_spp=reference_spp,
            log=log,
        )
    except SceneError as err:
        print(f"rtpy: error: {err}", file=sys.stderr)
        return 2
    if result.interrupted:
        import signal

        signal.signal(signal.SIGINT, signal.SIG_DFL)  # a second Ctrl-C ends at once
        log(f"rtpy bench: interrupted: keeping the {len(result.levels)} levels measured")
    if result.levels:
        print(format_table(result))
        print()
        print(format_series(result))
    files = write_outputs(result, out)
    png = plot(result, out)
    if png is None:
        log("rtpy bench: matplotlib is not installed, so no plot (pip install 'rtpy[plot]')")
    else:
        files.append(png)
    log("rtpy bench: wrote " + ", ".join(str(p) for p in files))
    return 130 if result.interrupted else 0
