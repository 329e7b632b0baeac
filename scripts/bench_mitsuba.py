"""rtpy's numpy backend against Mitsuba 3's compiled scalar_rgb path tracer on the
Cornell box: paths per second, whole process, and error at equal time.

    python scripts/bench_mitsuba.py [--width 128] [--spp 64] [--repeat 3] [--quick]

Mitsuba is not a dependency of rtpy: `pip install mitsuba` puts it beside rtpy for
this script, which says so and stops when it is missing.

The scene is rtpy's scenes/cornell.toml read from the file itself: every quad
becomes a Mitsuba rectangle with the same corners (its normal u x v, the side a
one-sided Mitsuba emitter lights), every lambertian a two-sided diffuse BSDF of the
same linear RGB albedo, the diffuse light an area emitter of the same radiance, the
camera the same pinhole (vertical field of view, look-from, look-at, up) with a box
pixel filter, as rtpy's uniform samples over each pixel's square. Both trace paths
with next-event estimation and MIS, the same max_depth (in both, the number of ray
segments of a path, the camera ray included), and Russian roulette from the same
depth (5); Mitsuba uses its default independent sampler.

Each renderer runs in a fresh process with 2 threads / 2 worker processes
(`python -m rtpy render ... -j 2 --backend numpy`; a child of this script imports
Mitsuba, renders and writes the image), --repeat times, alternating; the whole
process is timed (interpreter, imports, scene load, rendering, writing). rtpy
renders with its independent sampler, as Mitsuba does, so both do the same work:
each round's Mitsuba/rtpy time ratio is the paths/s ratio at equal spp, and the
median is reported. --sampler NAME adds a third renderer to every round, rtpy with
that sampler, whose error is the one compared with Mitsuba's.

The images are compared with one reference, rtpy's cached high-spp render
(rtpy.testing.reference, 4 independent renders of the numpy backend): first
Mitsuba's mean over the rounds is tested against it block by block
(rtpy.testing.statistics.block_z_test, alpha 0.01, Bonferroni); only when they
agree, that is when both renderers compute the same radiance, is the error
comparison meaningful (otherwise it is reported as void). The error is the RMSE
over all pixels and channels with the reference's own noise subtracted; the
efficiency is 1 / (MSE x seconds), which Monte Carlo noise keeps constant with
spp, so its ratio is the ratio of errors squared at equal time.
"""

from __future__ import annotations

import argparse
import math
import subprocess
import sys
import tempfile
import time
import tomllib
from functools import partial
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
SCENE = "cornell"
ALPHA = 0.01
RR_DEPTH = 5  # rtpy's russian_roulette default; Mitsuba's rr_depth default
MISSING = "Mitsuba not installed: pip install mitsuba"


def have_mitsuba() -> bool:
    import importlib.util

    return importlib.util.find_spec("mitsuba") is not None


def rectangle(q, u, v) -> list[list[float]]:
    """Mitsuba's rectangle ([-1, 1]^2 at z = 0, normal +z) moved onto the quad
    q + a u + b v (0 <= a, b <= 1): a 4x4 matrix whose columns are u/2, v/2, the
    unit normal u x v and the centre."""
    n = [u[1] * v[2] - u[2] * v[1], u[2] * v[0] - u[0] * v[2], u[0] * v[1] - u[1] * v[0]]
    length = math.sqrt(sum(c * c for c in n))
    centre = [q[k] + 0.5 * (u[k] + v[k]) for k in range(3)]
    columns = [[c / 2 for c in u], [c / 2 for c in v], [c / length for c in n], centre]
    return [[columns[c][r] for c in range(4)] for r in range(3)] + [[0.0, 0.0, 0.0, 1.0]]


def mitsuba_scene(scene_file: Path, width: int, spp: int, max_depth: int, seed: int) -> dict:
    """The Mitsuba scene dictionary of an rtpy scene file of quads, lambertian and
    diffuse_light materials (scenes/cornell.toml)."""
    import mitsuba as mi

    data = tomllib.loads(scene_file.read_text())
    cam = data["camera"]
    height = round(width / cam.get("aspect_ratio", 1.0))
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": max_depth, "rr_depth": RR_DEPTH},
        "sensor": {
            "type": "perspective",
            "fov": cam["vfov"],
            "fov_axis": "y",
            "to_world": mi.ScalarTransform4f().look_at(
                origin=cam["look_from"], target=cam["look_at"], up=cam.get("vup", [0, 1, 0])
            ),
            "sampler": {"type": "independent", "sample_count": spp, "seed": seed},
            "film": {
                "type": "hdrfilm",
                "width": width,
                "height": height,
                "pixel_format": "rgb",
                "rfilter": {"type": "box"},
            },
        },
    }
    for k, obj in enumerate(data["objects"]):
        if obj["type"] != "quad":
            raise SystemExit(f"{scene_file}: only quads are translated, not {obj['type']}")
        material = data["materials"][obj["material"]]
        shape = {
            "type": "rectangle",
            "to_world": mi.ScalarTransform4f(rectangle(obj["q"], obj["u"], obj["v"])),
        }
        if material["type"] == "lambertian":
            rgb = {"type": "rgb", "value": material["albedo"]}
            shape["bsdf"] = {
                "type": "twosided",
                "bsdf": {"type": "diffuse", "reflectance": rgb},
            }
        elif material["type"] == "diffuse_light":
            shape["emitter"] = {
                "type": "area",
                "radiance": {"type": "rgb", "value": material["emit"]},
            }
            shape["bsdf"] = {"type": "diffuse", "reflectance": {"type": "rgb", "value": 0.0}}
        else:
            raise SystemExit(f"{scene_file}: no Mitsuba twin for {material['type']}")
        scene[f"quad{k}"] = shape
    return scene


def mitsuba_child(out: str, width: int, spp: int, max_depth: int, seed: int, threads: int) -> None:
    """A whole Mitsuba render in this (fresh) process: the image to `out` (.npy)."""
    import drjit as dr
    import mitsuba as mi
    import numpy as np

    mi.set_variant("scalar_rgb")
    dr.set_thread_count(threads)
    from rtpy.io.bundled import resolve_scene

    scene = mi.load_dict(mitsuba_scene(resolve_scene(SCENE), width, spp, max_depth, seed))
    image = np.array(mi.render(scene, spp=spp, seed=seed), dtype=np.float64)
    np.save(out, image[..., :3])


def timed(command: list[str]) -> float:
    """Wall-clock seconds of a whole child process."""
    start = time.perf_counter()
    subprocess.run(command, check=True, capture_output=True)
    return time.perf_counter() - start


def rtpy_command(
    out: Path, width: int, spp: int, max_depth: int, seed: int, workers: int, sampler: str
):
    """`python -m rtpy render` of the scene with the numpy backend and `sampler`, the
    linear image to `out`."""
    return [
        sys.executable, "-m", "rtpy", "render", SCENE, "--backend", "numpy", "-q",
        "--width", str(width), "--spp", str(spp), "--max-depth", str(max_depth),
        "--seed", str(seed), "-j", str(workers), "-o", str(out.with_suffix(".png")),
        "--linear", str(out), "--sampler", sampler,
    ]  # fmt: skip


def mitsuba_command(out: Path, width: int, spp: int, max_depth: int, seed: int, threads: int):
    """This script's child rendering with Mitsuba (its own independent sampler)."""
    return [
        sys.executable, __file__, "--child", str(out), str(width), str(spp), str(max_depth),
        str(seed), str(threads),
    ]  # fmt: skip


def error(image, reference) -> float:
    """RMSE against the reference, its own noise subtracted (floored at 0)."""
    import numpy as np

    mse = float(np.mean((image - reference.image) ** 2)) - reference.noise_floor
    return math.sqrt(max(mse, 0.0))


def compare(
    width: int,
    spp: int,
    max_depth: int,
    repeat: int,
    workers: int,
    ref_spp: int,
    sampler: str | None = None,
) -> dict:
    """Run the renderers `repeat` times, alternating; the measurements as a dict.

    rtpy renders with the independent sampler, as Mitsuba does: the paths/s ratio
    compares the same work. With `sampler` naming another of rtpy's samplers, rtpy
    also renders with it in every round, and the error at equal time compares that
    one with Mitsuba's."""
    import numpy as np

    from rtpy.io.bundled import resolve_scene
    from rtpy.testing.reference import get_reference
    from rtpy.testing.statistics import block_z_test

    reference = get_reference(
        resolve_scene(SCENE), width, max_depth, ref_spp, log=lambda m: print(m, file=sys.stderr)
    )
    samplers = ["independent"] + ([sampler] if sampler and sampler != "independent" else [])
    commands = {f"rtpy {s}": partial(rtpy_command, sampler=s) for s in samplers}
    commands["mitsuba"] = mitsuba_command
    times = {name: [] for name in commands}
    images = {name: [] for name in commands}
    with tempfile.TemporaryDirectory() as tmp:
        for r in range(repeat):
            for k, (name, make) in enumerate(commands.items()):
                out = Path(tmp) / f"{k}-{r}.npy"
                times[name].append(timed(make(out, width, spp, max_depth, r + 1, workers)))
                images[name].append(np.load(out))
    ratios = sorted(m / t for m, t in zip(times["mitsuba"], times["rtpy independent"], strict=True))
    result = {
        "width": width,
        "spp": spp,
        "max_depth": max_depth,
        "workers": workers,
        "repeat": repeat,
        "reference": reference.source,
        "paths": width * reference.image.shape[0] * spp,
        "ratio": ratios[len(ratios) // 2],
        "against": f"rtpy {samplers[-1]}",  # the rtpy row whose error is compared
        "renderers": {},
    }
    for name in commands:
        stack = np.stack(images[name])
        seconds = float(np.median(times[name]))
        rmse = float(np.median([error(im, reference) for im in stack]))
        efficiency = 1 / (rmse**2 * seconds)
        result["renderers"][name] = {"seconds": seconds, "rmse": rmse, "efficiency": efficiency}
    if repeat > 1:
        stack = np.stack(images["mitsuba"])
        test = block_z_test(
            stack.mean(axis=0),
            stack.var(axis=0, ddof=1) / repeat,
            reference.image,
            reference.variance,
            ALPHA,
        )
        result["agree"] = test.passed
        result["agreement"] = "agree" if test.passed else test.worst("rtpy's reference")
    return result


def format_result(r: dict) -> list[str]:
    """The comparison's lines (a Markdown table and what it says)."""
    lines = [
        f"Cornell box {r['width']}x{r['width']}, {r['spp']} spp, max depth {r['max_depth']}, "
        f"{r['workers']} workers / threads, whole process, median of {r['repeat']} "
        "alternating runs",
        "",
        "| renderer | seconds | paths/s | RMSE | efficiency 1/(MSE s) |",
        "|---|---|---|---|---|",
    ]
    for name, m in r["renderers"].items():
        if name == "mitsuba":
            label = "Mitsuba 3 scalar_rgb (independent sampler)"
        else:
            label = f"rtpy numpy ({name.removeprefix('rtpy ')} sampler)"
        lines.append(
            f"| {label} | {m['seconds']:.2f} | {r['paths'] / m['seconds']:,.0f} "
            f"| {m['rmse']:.4g} | {m['efficiency']:,.0f} |"
        )
    lines.append("")
    lines.append(
        f"paths/s ratio rtpy / Mitsuba, both with the independent sampler: {r['ratio']:.2f}x "
        "(median of per-round ratios)"
    )
    against = r["against"]
    if r.get("agree") is None:
        lines.append("agreement not tested (needs --repeat 2 or more): errors not compared")
    elif r["agree"]:
        eff = r["renderers"][against]["efficiency"] / r["renderers"]["mitsuba"]["efficiency"]
        lines.append(
            f"Mitsuba's mean agrees with the reference ({r['reference']}; block z-test, "
            f"alpha {ALPHA}): efficiency ratio {against} / Mitsuba {eff:.2f}x, so at equal "
            f"time {against}'s RMSE is {1 / math.sqrt(eff):.2f} of Mitsuba's"
        )
    else:
        lines.append(f"Mitsuba's image differs from rtpy's: {r['agreement']}; errors not compared")
    return lines


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--width", type=int, default=128)
    parser.add_argument("--spp", type=int, default=64)
    parser.add_argument("--max-depth", type=int, default=8)
    parser.add_argument("--repeat", type=int, default=3)
    parser.add_argument("--workers", type=int, default=2, help="rtpy processes, Mitsuba threads")
    parser.add_argument("--reference-spp", type=int, default=4096)
    parser.add_argument(
        "--sampler", help="also render rtpy with --sampler NAME; its error is compared"
    )
    parser.add_argument("--quick", action="store_true", help="32x32, 16 spp, 2 rounds")
    args = parser.parse_args(argv)
    from rtpy.cli.bench.machine import compile_bytecode

    compile_bytecode()  # whole processes are timed: as an installed rtpy starts
    if not have_mitsuba():
        print(MISSING)
        return 0
    if args.quick:
        args.width, args.spp, args.repeat, args.reference_spp = 32, 16, 2, 1024
    result = compare(
        args.width,
        args.spp,
        args.max_depth,
        args.repeat,
        args.workers,
        args.reference_spp,
        args.sampler,
    )
    print("\n".join(format_result(result)))
    return 0


if __name__ == "__main__":
    if sys.argv[1:2] == ["--child"]:
        out, *numbers = sys.argv[2:]
        mitsuba_child(out, *map(int, numbers))
    else:
        sys.exit(main())
