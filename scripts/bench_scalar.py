"""Scalar-backend speed on the week-8 scene (issue 2's benchmark).

    python scripts/bench_scalar.py [--scene week08_three_balls] [--width 96] [--spp 16]
                                   [--max-depth 5] [--workers 1,2]

Renders the scene (default week08_three_balls) with each worker count (default 1
and then 2 processes) in one run and prints paths/s (camera paths per
wall-clock second) for each and, with more than one count, the speed-ups.
"""

from __future__ import annotations

import argparse
import time

import rtpy


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scene", default="week08_three_balls")
    parser.add_argument("--width", type=int, default=96)
    parser.add_argument("--spp", type=int, default=16)
    parser.add_argument("--max-depth", type=int, default=5)
    parser.add_argument(
        "--workers",
        type=lambda text: [int(n) for n in text.split(",")],
        default=[1, 2],
        help="comma-separated worker counts to run, in order (default 1,2)",
    )
    args = parser.parse_args()
    scene = rtpy.load_scene(args.scene)
    results = {}
    for workers in args.workers:
        cpu = time.process_time()
        image = rtpy.render(
            scene, width=args.width, spp=args.spp, max_depth=args.max_depth, workers=workers
        )
        cpu = time.process_time() - cpu
        stats = image.stats
        results[workers] = stats["paths_per_second"]
        line = (
            f"{args.scene} {image.width}x{image.height} {args.spp} spp depth {args.max_depth} "
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
