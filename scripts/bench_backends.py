"""Scalar versus numpy backend speed.

    python scripts/bench_backends.py [--quick] [--repeat N]

In one run, renders with both backends and prints a Markdown table of paths/s
(camera paths per wall-clock second), the numpy/scalar ratio and each render's
peak resident memory (every render runs in a fresh process, so the number is its
own; with workers, the largest process):

1. cornell and week08_three_balls, scalar and numpy, 1 worker each, "path"
   integrator, the scene's max_depth (week08: 5, as scripts/bench_scalar.py).
   The scalar backend renders fewer paths (it is slow); paths/s does not depend
   on the count once there are a few thousand.
2. cornell at 128x128 with the numpy backend on 1 and 2 workers.
3. rtiow_cover (487 spheres) against week08_three_balls (5 spheres) with the numpy
   backend at the same size and spp: the cost per path of hundreds of spheres.

Each configuration is rendered --repeat times (default 3), the pairs being compared
interleaved (scalar, numpy, scalar, numpy, ...), and the fastest run of each is
reported: on a machine shared with other jobs the load changes from second to
second, and the best of a few runs is the least disturbed measurement of each.

--quick renders less (a smoke test of the script, not a measurement).
"""

from __future__ import annotations

import argparse
import multiprocessing

import rtpy


def _render(queue, name: str, backend: str, workers: int, kw: dict) -> None:
    scene = rtpy.load_scene(name)
    image = rtpy.render(scene, backend=backend, workers=workers, **kw)
    queue.put((image.width, image.height, image.stats))


def run(name: str, backend: str, workers: int = 1, **kw) -> dict:
    """Render in a fresh process; returns the stats plus size and peak RSS (MB)."""
    ctx = multiprocessing.get_context("spawn")
    queue = ctx.Queue()
    proc = ctx.Process(target=_render, args=(queue, name, backend, workers, kw))
    proc.start()
    width, height, stats = queue.get()
    proc.join()
    return {**stats, "size": f"{width}x{height}", "rss": stats["peak_rss_mb"], "spp": kw["spp"]}


def best(runs: list[dict]) -> dict:
    """The fastest of several runs of one configuration (its peak RSS the largest)."""
    fastest = max(runs, key=lambda r: r["paths_per_second"])
    return {**fastest, "rss": max(r["rss"] for r in runs)}


def interleaved(repeat: int, *configs: tuple) -> list[dict]:
    """best() of `repeat` runs of each config (args of run), alternating between them."""
    runs: list[list[dict]] = [[] for _ in configs]
    for _ in range(repeat):
        for i, (args, kw) in enumerate(configs):
            runs[i].append(run(*args, **kw))
    return [best(r) for r in runs]


def row(scene: str, backend: str, workers: int, r: dict, ratio: str = "") -> str:
    return (
        f"| {scene} | {r['size']} | {r['spp']} | {backend} | {workers} | {r['seconds']:.2f} s "
        f"| {r['paths_per_second']:,.0f} | {ratio} | {r['rss']:.0f} MB |"
    )


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--quick", action="store_true", help="small renders (smoke test)")
    parser.add_argument("--repeat", type=int, default=3, help="runs per configuration")
    args = parser.parse_args()
    q = 4 if args.quick else 1
    n = 1 if args.quick else max(1, args.repeat)
    print("| scene | size | spp | backend | workers | time | paths/s | numpy/scalar | peak RSS |")
    print("|---|---|---|---|---|---|---|---|---|")

    # 1. Both backends on the same scenes.
    cases = [
        ("cornell", dict(width=64 // q, spp=4), dict(width=128, spp=64 // q)),
        (
            "week08_three_balls",
            dict(width=96 // q, spp=16, max_depth=5),
            dict(width=384, spp=64 // q, max_depth=5),
        ),
    ]
    for name, scalar_kw, numpy_kw in cases:
        s, nb = interleaved(n, ((name, "scalar"), scalar_kw), ((name, "numpy"), numpy_kw))
        ratio = nb["paths_per_second"] / s["paths_per_second"]
        print(row(name, "scalar", 1, s))
        print(row(name, "numpy", 1, nb, f"**{ratio:.0f}x**"))

    # 2. Workers on cornell 128x128.
    kw = dict(width=128, spp=64 // q)
    one, two = interleaved(n, (("cornell", "numpy", 1), kw), (("cornell", "numpy", 2), kw))
    print(row("cornell", "numpy", 1, one))
    print(row("cornell", "numpy", 2, two))

    # 3. Hundreds of spheres against five.
    kw = dict(width=200, spp=32 // q)
    few, many = interleaved(
        n, (("week08_three_balls", "numpy"), kw), (("rtiow_cover", "numpy"), kw)
    )
    print(row("week08_three_balls", "numpy", 1, few))
    print(row("rtiow_cover", "numpy", 1, many))
    print()
    print(
        f"cost per path, rtiow_cover (487 spheres) / week08_three_balls (5 spheres): "
        f"{few['paths_per_second'] / many['paths_per_second']:.1f}x; "
        f"cornell 128x128 speed-up with 2 workers: "
        f"{two['paths_per_second'] / one['paths_per_second']:.2f}x"
    )


if __name__ == "__main__":
    main()
