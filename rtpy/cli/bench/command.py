"""The command `python -m rtpy bench`: its options, checked before anything runs."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from ...engine.signals import exit_status
from ...io.bundled import resolve_scene
from ...io.image import OutputError, WriteError
from ...io.outputs import check_folder
from ...io.scene_file import SceneError
from ...render_settings import SETTINGS, SettingError
from ...sampler import SAMPLERS
from ...testing.analytic_scenes import ANALYTIC_SCENES
from ...testing.reference import DEFAULT_REFERENCE_SPP
from .report import format_sampler_efficiency, format_series, format_table, plot, write_outputs
from .run import DEFAULT_SPP, run_bench
from .scenes import ALL_VARIANTS, BACKENDS, VARIANTS

QUICK = {"width": 16, "spp": (1, 4, 16), "repeats": 2}


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
        help=f"comma-separated variants: {','.join(ALL_VARIANTS)} (default "
        f"{','.join(VARIANTS)}; the last three compare stop criteria: docs/bench.md)",
    )
    b.add_argument(
        "--samplers",
        default=None,
        help=f"comma-separated samplers: {','.join(SAMPLERS)} (default independent; "
        "docs/samplers.md)",
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
    if not values:
        raise BenchUsageError(f"--spp: expected whole numbers such as 1,4,16,64; got {text!r}")
    return [_setting("spp", v, "--spp") for v in values]


def _setting(key: str, value, option: str):
    try:
        return SETTINGS[key].check(value)
    except SettingError as e:
        raise BenchUsageError(e.for_option(option)) from None


def _default(given, default):
    """The option's value as given, or `default` when it was not given."""
    return default if given is None else given


def _options(args: argparse.Namespace) -> dict:
    """run_bench's arguments from the command line's, every one checked."""
    # `is None`, not `or`: a 0 given is refused, not replaced by the default
    repeats = _default(args.repeats, QUICK["repeats"] if args.quick else 4)
    if repeats < 2:
        raise BenchUsageError("--repeats: at least 2 (the bias test needs the spread)")
    if args.workers < 1 or args.reference_spp < 1:
        raise BenchUsageError("--workers and --reference-spp must be >= 1")
    if args.budget is not None and not args.budget > 0:
        raise BenchUsageError("--budget: expected seconds > 0")
    scenes = args.scenes or list(ANALYTIC_SCENES)
    for name in scenes:
        if name not in ANALYTIC_SCENES:
            resolve_scene(name)
    try:
        check_folder(args.out, "--out")
        if args.cache:
            check_folder(args.cache, "--cache")
    except OutputError as err:
        raise BenchUsageError(str(err)) from None
    return {
        "scenes": scenes,
        "backends": _split(args.backends, BACKENDS, "backends") or ["numpy"],
        "variants": _split(args.integrators, tuple(ALL_VARIANTS), "integrators") or list(VARIANTS),
        "samplers": _split(args.samplers, tuple(SAMPLERS), "samplers") or ["independent"],
        "spps": _spp_list(args.spp) if args.spp else (QUICK["spp"] if args.quick else DEFAULT_SPP),
        "budget": args.budget,
        "repeats": repeats,
        "width": _setting(
            "width", _default(args.width, QUICK["width"] if args.quick else 64), "--width"
        ),
        "workers": args.workers,
        "cache": Path(args.cache) if args.cache else None,
        "reference_spp": min(args.reference_spp, 256) if args.quick else args.reference_spp,
    }


def command_bench(args: argparse.Namespace) -> int:
    """Run the bench, print its tables, write its files; 2 for bad options (nothing
    written), 1 when a file cannot be written, 130 when Ctrl-C stopped it and 143
    when SIGTERM did (what was measured is written)."""

    def log(msg: str) -> None:
        print(msg, file=sys.stderr)

    try:
        options = _options(args)
        result = run_bench(**options, log=log)
    except (BenchUsageError, SceneError) as err:
        print(f"rtpy: error: {err}", file=sys.stderr)
        return 2
    if result.interrupted:  # a second signal ends at once (rtpy.engine.signals)
        log(f"rtpy bench: interrupted: keeping the {len(result.levels)} levels measured")
    if result.levels:
        print(format_table(result))
        print()
        print(format_series(result))
        gains = format_sampler_efficiency(result)
        if gains:
            print()
            print(gains)
        if args.quick:
            log("rtpy bench: --quick renders take milliseconds: its timings are not meaningful")
    try:
        files = write_outputs(result, Path(args.out))
        png = plot(result, Path(args.out), quick=args.quick)
    except WriteError as err:
        print(f"rtpy: error: {err}", file=sys.stderr)
        return 1
    if png is None:
        log("rtpy bench: matplotlib is not installed, so no plot (pip install 'rtpy[plot]')")
    else:
        files.append(png)
    log("rtpy bench: wrote " + ", ".join(str(p) for p in files))
    return exit_status() if result.interrupted else 0
