"""Scalar-backend speed on the week-8 scene (issue 2's benchmark).

    python scripts/bench_scalar.py [--scene week08_three_balls] [--width 96] [--spp 16]
                                   [--max-depth 5] [--workers 1,2]
    python scripts/bench_scalar.py --against OTHER_TREE [--pairs 8] [--scene ...] [--width 96]

Renders the scene (default week08_three_balls) with each worker count (default 1
and then 2 processes) in one run and prints paths/s (camera paths per
wall-clock second) for each and, with more than one count, the speed-ups.

With --against, compares this checkout with another one (a directory holding an
rtpy/ package, e.g. `git worktree add /tmp/old COMMIT`) side by side: pairs of fresh
processes, one per checkout, in alternating order, each timing one in-process
`rtpy.render(scene, width=..., workers=1, backend="scalar")` (the scene's own spp and
depth unless --spp/--max-depth are given) in CPU seconds (time.process_time). It
prints each pair's ratio this / other and their median: below 1 this checkout is
faster. On a shared machine the median of the pair ratios is the figure to quote.
"""

from __future__ import annotations

import argparse
import os
import statistics
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import rtpy

HERE = Path(__file__).resolve().parent.parent  # the checkout this script belongs to

# One in-process render in a fresh interpreter: prints the CPU seconds it took and
# the rtpy package it imported (to show which checkout ran).
CHILD = """
import sys, time
import rtpy
scene = rtpy.load_scene(sys.argv[1])
options = dict(width=int(sys.argv[2]), workers=1, backend="scalar")
if sys.argv[3] != "-":
    options["spp"] = int(sys.argv[3])
if sys.argv[4] != "-":
    options["max_depth"] = int(sys.argv[4])
cpu = time.process_time()
rtpy.render(scene, **options)
print(time.process_time() - cpu, rtpy.__file__)
"""


def child_cpu(tree: Path, args: argparse.Namespace) -> float:
    """CPU seconds of one render by the rtpy package in `tree`, in a fresh process."""
    env = dict(os.environ, PYTHONPATH=str(tree))
    argv = [args.scene, str(args.width)]
    argv += ["-" if value is None else str(value) for value in (args.spp, args.max_depth)]
    with tempfile.TemporaryDirectory() as cwd:  # not a checkout: PYTHONPATH decides
        out = subprocess.run(
            [sys.executable, "-c", CHILD, *argv],
            env=env,
            cwd=cwd,
            capture_output=True,
            text=True,
            check=True,
        ).stdout.split()
    imported = Path(out[1]).resolve()
    if tree.resolve() not in imported.parents:
        raise SystemExit(f"{tree}: the child imported {imported} instead")
    return float(out[0])


def compare(args: argparse.Namespace) -> None:
    """Pairs of renders, this checkout and args.against in alternating order."""
    other = Path(args.against)
    if not (other / "rtpy" / "__init__.py").is_file():
        raise SystemExit(f"--against {other}: no rtpy/ package there")
    ratios = []
    for k in range(args.pairs):
        order = [HERE, other] if k % 2 == 0 else [other, HERE]
        cpu = {tree: child_cpu(tree, args) for tree in order}
        ratios.append(cpu[HERE] / cpu[other])
        print(f"pair {k + 1}: this {cpu[HERE]:.3f} s, other {cpu[other]:.3f} s, {ratios[-1]:.3f}")
    print(
        f"{args.scene} {args.width} px wide, 1 worker, CPU time this / other: median "
        f"{statistics.median(ratios):.3f} (min {min(ratios):.3f}, max {max(ratios):.3f}, "
        f"{len(ratios)} pairs)"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default="week08_three_balls")
    parser.add_argument("--width", type=int, default=96)
    parser.add_argument("--spp", type=int, help="default 16 (--against: the scene's)")
    parser.add_argument("--max-depth", type=int, help="default 5 (--against: the scene's)")
    parser.add_argument(
        "--workers",
        type=lambda text: [int(n) for n in text.split(",")],
        default=[1, 2],
        help="comma-separated worker counts to run, in order (default 1,2)",
    )
    parser.add_argument("--against", metavar="OTHER_TREE", help="compare with that checkout")
    parser.add_argument("--pairs", type=int, default=8, help="with --against (default 8)")
    args = parser.parse_args()
    if args.against:
        compare(args)
        return
    spp = 16 if args.spp is None else args.spp
    max_depth = 5 if args.max_depth is None else args.max_depth
    scene = rtpy.load_scene(args.scene)
    results = {}
    for workers in args.workers:
        cpu = time.process_time()
        image = rtpy.render(scene, width=args.width, spp=spp, max_depth=max_depth, workers=workers)
        cpu = time.process_time() - cpu
        stats = image.stats
        results[workers] = stats["paths_per_second"]
        line = (
            f"{args.scene} {image.width}x{image.height} {spp} spp depth {max_depth} "
            f"workers {workers}: {stats['seconds']:.2f} s, {stats['paths_per_second']:,.0f} paths/s"
        )
        if workers == 1:
            line += f" (CPU {stats['paths'] / cpu:,.0f} paths per CPU-second)"
        print(line)
    first = args.workers[0]
    for workers in args.workers[1:]:
        print(f"speed-up with {workers} workers: {results[workers] / results[first]:.2f}x")


if __name__ == "__main__":
    main()
