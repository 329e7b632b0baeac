"""`rtpy bench`'s measurements: render each level of each series and measure its
time, memory and error (rtpy.cli.bench.convergence) against its reference."""

from __future__ import annotations

import math
import time
from pathlib import Path

import numpy as np

from ...engine import renderer  # noqa: F401  (rtpy loads it on first use: here, before any timing)
from ...testing.reference import DEFAULT_REFERENCE_SPP, Reference
from ...testing.statistics import peak_memory_mb, reset_peak_memory
from .convergence import (
    ALPHA,
    ROUNDING,
    SLOPE_TOLERANCE,
    BenchResult,
    Fit,
    Level,
    error_stats,
    fit_slope,
    series_name,
    z_score,
)
from .machine import machine
from .scenes import ALL_VARIANTS, VARIANTS, BenchScene, effective_depth, load_bench_scene

DEFAULT_SPP = (1, 4, 16, 64)
MAX_BUDGET_SPP = 1 << 16


def render_once(
    bs: BenchScene,
    backend: str,
    variant: str,
    spp: int,
    seed: int,
    workers: int,
    sampler: str = "independent",
):
    """(linear image, seconds, peak RSS in MB) of one render."""
    from ... import render

    reset_peak_memory()
    start = time.perf_counter()
    image = render(
        bs.scene,
        camera=bs.camera,
        backend=backend,
        spp=spp,
        seed=seed,
        workers=workers,
        sampler=sampler,
        # the variant's own depth or roulette, else the scene's
        **{
            "max_depth": bs.max_depth,
            "russian_roulette": bs.russian_roulette,
            **ALL_VARIANTS[variant],
        },
    )
    seconds = time.perf_counter() - start
    if image.interrupted:  # Ctrl-C inside the render: a partial image is no measurement
        raise KeyboardInterrupt
    return image.linear, seconds, peak_memory_mb()


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
    sampler: str = "independent",
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
            render_seed = seed + 1000 * k + r
            img, sec, peak = render_once(bs, backend, variant, spp, render_seed, workers, sampler)
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
            sampler=sampler,
        )
        levels.append(lv)
        log(f"  {series_name(lv)} spp {spp}: {seconds:.3f} s/render, relMSE {lv.rel_mse:.3g}")
        k += 1
        if budget is not None:
            # The next level costs about twice this one.
            if spent + 2.0 * sum(times) > budget or spp * 2 > MAX_BUDGET_SPP:
                if k >= 2:
                    break
            spp *= 2
    return levels


def fit_series(levels: list[Level], ref: Reference) -> Fit:
    """The slope of log MSE against log spp of one series' levels (none when the
    error is zero: below ROUNDING of the reference's scale)."""
    scale = float(np.abs(ref.image[ref.mask]).mean())
    slope, se = fit_slope(
        [lv.spp for lv in levels],
        [lv.mse for lv in levels],
        [lv.mse_se for lv in levels],
        zero=(ROUNDING * scale) ** 2,
    )
    note = "" if slope is not None else "no slope: error is zero (exact) or one level"
    first = levels[0]
    return Fit(
        first.scene, first.backend, first.integrator, slope, se, len(levels), note, first.sampler
    )


def run_bench(
    scenes: list[str],
    backends=("numpy",),
    variants=tuple(VARIANTS),
    spps=DEFAULT_SPP,
    *,
    samplers=("independent",),
    budget: float | None = None,
    repeats: int = 4,
    width: int | None = 64,
    workers: int = 1,
    cache: Path | None = None,
    reference_spp: int = DEFAULT_REFERENCE_SPP,
    log=print,
    seed: int = 1,
) -> BenchResult:
    """Measure every series (scene x backend x variant x sampler) and decide significance over
    all of them; a Ctrl-C stops the run and keeps the levels measured so far
    (BenchResult.interrupted)."""
    result = BenchResult(
        settings={
            "scenes": list(scenes),
            "backends": list(backends),
            "integrators": list(variants),
            "samplers": list(samplers),
            "spp": None if budget is not None else list(spps),
            "budget_seconds": budget,
            "repeats": repeats,
            "width": width,
            "workers": workers,
            "seed": seed,
            "alpha": ALPHA,
            "slope_tolerance": SLOPE_TOLERANCE,
            "date": time.strftime("%Y-%m-%d %H:%M:%S"),
            "machine": machine(),
        }
    )

    try:
        for name in scenes:
            bs = load_bench_scene(name, width, cache, reference_spp, log)
            refs: dict[int, Reference] = {}
            series = [(b, v, s) for b in backends for v in variants for s in samplers]
            for backend, variant, sampler in series:
                depth = effective_depth(variant, bs.max_depth)
                if depth not in refs:
                    refs[depth] = bs.reference_for(depth)
                levels: list[Level] = []
                try:
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
                        levels=levels,
                        sampler=sampler,
                    )
                finally:  # also the levels of a series that Ctrl-C stopped
                    if levels:
                        result.levels.extend(levels)
                        result.fits.append(fit_series(levels, refs[depth]))
    except KeyboardInterrupt:
        result.interrupted = True
    result.finish()
    return result
