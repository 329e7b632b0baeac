"""rtpy's scalar backend against the course's own week-8 code, on the course's scene.

    python scripts/bench_course.py [COURSE_DIR] [--width 64] [--spp 2] [--max-depth 5]
                                   [--repeat 3] [--rtpy DIR ...]

COURSE_DIR is a checkout of the course's week-8 repository
(KUGA-01418283-Raytracing/RT-python-week08: RT_utility.py, RT_material.py, ...),
which stays outside this repository: the script imports its modules from there.
Without it (or when it is missing) the course's row is skipped with a message.

The scene is the course's week-8 scene (main.py, renderPhong): a checkered ground
sphere, three balls, a small lamp sphere above them, a dark grey background, camera
from (-2, 2, 1) toward (0, 0, -1), vfov 60, 16:9. The course leaves the balls'
material to the student (its Phong has empty scattering() and BRDF()); here both
renderers give them the normalised Phong lobe of scenes/week08_phong.toml
(exponents 0.8, 8 and 30, kd 0.6, ks 0.4), the course's by filling in its two
methods with the course's own Vec3 API. rtpy renders the same scene built in code,
with its "path" integrator, one worker process.

Both render the same width, spp and max_depth, each in a fresh process (the course's
with its own Renderer, which samples the lamp as a point light at every bounce),
--repeat times, alternating (course, rtpy, course, rtpy, ...); the fastest run of
each is reported, since on a shared machine the best of a few runs is the least
disturbed one. It prints, for each, the render's wall-clock and CPU seconds and
paths/s (camera paths per CPU second of rendering: other processes on the machine
slow the wall clock far more than the CPU time), and the ratio rtpy / course.
--rtpy DIR adds a row for another rtpy checkout (for example the base of a change),
measured in the same rounds.

--shares profiles rtpy's render instead (with py-spy, `pip install py-spy`; it
renders --repeat times in one process) and prints where its time goes: in the
solution regions' own lines, in the Vec3 methods those lines call, and elsewhere
(the functions that take most), and how much faster rtpy could be at most with
nothing but the regions and their Vec3 calls left.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import re
import shutil
import subprocess
import sys
import tempfile
import time
import types
from collections import Counter
from pathlib import Path

# The scene, in numbers both renderers use.
LOOK_FROM, LOOK_AT, VUP = (-2.0, 2.0, 1.0), (0.0, 0.0, -1.0), (0.0, 1.0, 0.0)
VFOV, FOCUS_DISTANCE = 60.0, 10.0
BACKGROUND = (0.01, 0.01, 0.01)
CHECKER = (0.32, (0.2, 0.2, 0.2), (0.9, 0.9, 0.9))  # cell size, even, odd
GROUND = ((0.0, -100.5, -1.0), 100.0)
BALLS = [  # center, albedo, exponent
    ((-1.0, 0.0, -1.0), (0.7, 0.15, 0.1), 0.8),
    ((0.0, 0.0, -1.0), (0.1, 0.5, 0.15), 8.0),
    ((1.0, 0.0, -1.0), (0.1, 0.2, 0.6), 30.0),
]
BALL_RADIUS, KD, KS = 0.5, 0.6, 0.4
LAMP = ((0.0, 1.0, 0.0), 0.05, (0.9, 0.9, 0.9))  # center, radius, emitted radiance


def render_course(course_dir: str, width: int, spp: int, max_depth: int, seed: int) -> dict:
    """Render with the course's modules; returns seconds and paths."""
    sys.path.insert(0, course_dir)
    # The course's progress bar needs the `progressbar` package; rendering does not.
    pbar = types.ModuleType("RT_pbar")
    pbar.start_animated_marker = lambda n: types.SimpleNamespace(update=lambda k: None)
    sys.modules["RT_pbar"] = pbar
    import numpy as np
    import RT_camera as rtc
    import RT_integrator as rti
    import RT_light as rtl
    import RT_material as rtm
    import RT_object as rto
    import RT_ray as rtr
    import RT_renderer as rtren
    import RT_scene as rts
    import RT_texture as rtt
    import RT_utility as rtu

    vec, dot = rtu.Vec3, rtu.Vec3.dot_product

    class Phong(rtm.Phong):
        """The course's Phong with the student's two methods: BRDF() the normalised
        lobe kd albedo / pi + ks (n + 2) / (2 pi) max(0, r . v)^n, scattering() a
        direction about the normal as the course's diffuse materials draw it."""

        def scattering(self, ray_in, hit):
            normal = hit.getNormal()
            direction = normal + vec.random_vec3_unit()
            if direction.near_zero():
                direction = normal
            scattered = rtr.Ray(hit.getP(), direction)
            return rtu.Scatterinfo(scattered, self.BRDF(ray_in, scattered, hit))

        def BRDF(self, ray_view, ray_light, hit):
            to_light = vec.unit_vector(ray_light.getDirection())
            to_view = -vec.unit_vector(ray_view.getDirection())
            cos_r = max(0.0, dot(rtm.reflect(-to_light, hit.getNormal()), to_view))
            lobe = self.ks * (self.alpha + 2.0) / (2.0 * math.pi) * cos_r**self.alpha
            diffuse = self.color_albedo * (self.kd / math.pi)
            return diffuse + rtu.Color(lobe, lobe, lobe)

    np.random.seed(seed)  # the course draws from numpy's global generator
    camera = rtc.Camera()
    camera.aspect_ratio = 16.0 / 9.0
    camera.img_width = width
    camera.samples_per_pixel = spp
    camera.max_depth = max_depth
    camera.vertical_fov = VFOV
    camera.look_from, camera.look_at, camera.vec_up = vec(*LOOK_FROM), vec(*LOOK_AT), vec(*VUP)
    camera.init_camera(0.0, FOCUS_DISTANCE)

    scene = rts.Scene(rtu.Color(*BACKGROUND))
    cell, even, odd = CHECKER
    checker = rtt.CheckerTexture(cell, rtu.Color(*even), rtu.Color(*odd))
    scene.add_object(rto.Sphere(vec(*GROUND[0]), GROUND[1], rtm.TextureColor(checker)))
    for center, albedo, exponent in BALLS:
        material = Phong(rtu.Color(*albedo), KD, KS, exponent)
        scene.add_object(rto.Sphere(vec(*center), BALL_RADIUS, material))
    center, radius, emit = LAMP
    scene.add_object(rto.Sphere(vec(*center), radius, rtl.Diffuse_light(rtu.Color(*emit))))

    renderer = rtren.Renderer(camera, rti.Integrator(), scene)
    return timed(renderer.render, lambda _: camera.img_width * camera.img_height * spp)


def render_rtpy(width: int, spp: int, max_depth: int, seed: int, workers: int = 1) -> dict:
    """Render with the rtpy on sys.path, scalar backend, `workers` processes."""
    import rtpy
    import rtpy.engine.renderer  # noqa: F401  imported here, they are not part of the render's time)
    import rtpy.io.preview  # noqa: F401  (these two rtpy.render imports on first use:
    from rtpy.materials import DiffuseLight, Lambertian, Phong

    scene = rtpy.Scene(background=rtpy.Color(*BACKGROUND))
    cell, even, odd = CHECKER
    checker = rtpy.CheckerTexture(cell, rtpy.Color(*even), rtpy.Color(*odd))
    scene.add_object(rtpy.Sphere(rtpy.Vec3(*GROUND[0]), GROUND[1], Lambertian(checker)))
    for center, albedo, exponent in BALLS:
        material = Phong(rtpy.Color(*albedo), kd=KD, ks=KS, exponent=exponent)
        scene.add_object(rtpy.Sphere(rtpy.Vec3(*center), BALL_RADIUS, material))
    center, radius, emit = LAMP
    scene.add_object(rtpy.Sphere(rtpy.Vec3(*center), radius, DiffuseLight(rtpy.Color(*emit))))
    camera = rtpy.Camera(
        look_from=rtpy.Vec3(*LOOK_FROM),
        look_at=rtpy.Vec3(*LOOK_AT),
        vup=rtpy.Vec3(*VUP),
        vfov=VFOV,
        width=width,
        focus_distance=FOCUS_DISTANCE,
    )

    def render():
        return rtpy.render(
            scene,
            camera=camera,
            spp=spp,
            max_depth=max_depth,
            seed=seed,
            workers=workers,
            quiet=True,
        )

    return timed(render, lambda image: image.width * image.height * spp)


def timed(render, count_paths) -> dict:
    """Run render(); its wall-clock and CPU seconds and count_paths(its result)."""
    wall, cpu = time.perf_counter(), time.process_time()
    result = render()
    wall, cpu = time.perf_counter() - wall, time.process_time() - cpu
    return {"seconds": wall, "cpu_seconds": cpu, "paths": count_paths(result)}


def run_child(
    kind: str, width: int, spp: int, max_depth: int, course_dir: str | None, rtpy_dir=None
) -> dict:
    """One render in a fresh Python process; its result."""
    command = [sys.executable, __file__, "--child", kind, "--width", str(width)]
    command += ["--spp", str(spp), "--max-depth", str(max_depth)]
    if kind == "course":
        command.append(course_dir)
    env = dict(os.environ)
    if rtpy_dir is not None:
        env["PYTHONPATH"] = os.pathsep.join(filter(None, [rtpy_dir, env.get("PYTHONPATH")]))
    out = subprocess.run(command, env=env, check=True, capture_output=True, text=True).stdout
    return json.loads(out.strip().splitlines()[-1])


def has_course(course_dir: str | None) -> bool:
    return bool(course_dir) and (Path(course_dir) / "RT_material.py").is_file()


def measure(
    course_dir: str | None,
    width: int,
    spp: int,
    max_depth: int,
    repeat: int,
    others: tuple[str, ...] = (),
) -> dict[str, dict]:
    """The fastest of `repeat` alternating runs of each renderer: label -> its result
    (paths_per_second per CPU second), "course" only with a checkout at course_dir,
    "rtpy DIR" for each other rtpy checkout."""
    rows: list[tuple[str, str, str | None]] = []  # (label, kind, rtpy dir)
    if has_course(course_dir):
        rows.append(("course", "course", None))
    rows.append(("rtpy", "rtpy", None))
    rows += [(f"rtpy {d}", "rtpy", str(Path(d).resolve())) for d in others]
    best: dict[str, dict] = {}
    for _ in range(max(1, repeat)):
        for label, kind, rtpy_dir in rows:
            r = run_child(kind, width, spp, max_depth, course_dir, rtpy_dir)
            r["paths_per_second"] = r["paths"] / r["cpu_seconds"]
            if label not in best or r["paths_per_second"] > best[label]["paths_per_second"]:
                best[label] = r
    return best


# A frame of py-spy's raw output: "function (file:line)".
FRAME = re.compile(r"^(?P<function>.*) \((?P<file>.*):(?P<line>\d+)\)$")


def region_lines() -> dict[str, set[int]]:
    """rtpy file ("rtpy/vec3.py") -> numbers (1-based) of the lines inside its
    solution regions, markers excluded."""
    import rtpy
    from rtpy.grading.assignment import find_regions

    lines: dict[str, set[int]] = {}
    for r in find_regions(Path(rtpy.__file__).resolve().parents[1]):
        lines.setdefault(r.path.as_posix(), set()).update(range(r.begin + 2, r.end + 1))
    return lines


def classify(raw: str, regions: dict[str, set[int]]) -> tuple[Counter, Counter, int]:
    """From py-spy's raw stacks: samples per share ("regions", "Vec3 from regions",
    "elsewhere"), samples per function elsewhere, and the samples inside the render
    (stacks through scalar_backend.render_unit). A sample belongs to its innermost rtpy
    frame (builtins such as math.sqrt count for their caller); a Vec3 method outside
    the regions called from a region's line is "Vec3 from regions"."""
    shares, elsewhere, total = Counter(), Counter(), 0
    for row in raw.splitlines():
        stack, _, count = row.rpartition(" ")
        frames = []
        for text in stack.split(";"):
            m = FRAME.match(text)
            file = m["file"].replace("\\", "/") if m else ""
            if "rtpy/" in file:
                rel = "rtpy/" + file.rpartition("rtpy/")[2]
                frames.append((m["function"], rel, int(m["line"])))
        if not any(f[0] == "render_unit" for f in frames):
            continue  # start-up, imports, the image's assembly
        n = int(count)
        total += n
        function, rel, line = frames[-1]
        caller = frames[-2] if len(frames) > 1 else None
        if line in regions.get(rel, ()):
            shares["regions"] += n
        elif rel == "rtpy/vec3.py" and caller and caller[2] in regions.get(caller[1], ()):
            shares["Vec3 from regions"] += n
        else:
            shares["elsewhere"] += n
            elsewhere[f"{function} ({rel})"] += n
    return shares, elsewhere, total


def print_shares(width: int, spp: int, max_depth: int, renders: int) -> None:
    """Profile `renders` renders of rtpy in one process with py-spy; print the shares."""
    # On the PATH, or beside this Python (a virtual environment not activated).
    py_spy = shutil.which("py-spy") or shutil.which("py-spy", path=Path(sys.executable).parent)
    if py_spy is None:
        print("--shares needs py-spy on the PATH: pip install py-spy")
        return
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "stacks.txt"
        command = [py_spy, "record", "--rate", "1000", "--format", "raw", "--output", str(out)]
        command += ["--", sys.executable, __file__, "--child", "rtpy", "--renders", str(renders)]
        command += ["--width", str(width), "--spp", str(spp), "--max-depth", str(max_depth)]
        run = subprocess.run(command, capture_output=True, text=True)
        if run.returncode != 0:
            lines = (run.stderr or run.stdout).strip().splitlines() or ["no output"]
            print(f"py-spy failed (exit {run.returncode}): {lines[-1]}")
            return
        shares, elsewhere, total = classify(out.read_text(), region_lines())
    if not total:
        print("py-spy recorded no samples inside the render")
        return
    print(f"rtpy's render, {renders} x width {width}, {spp} spp: {total} samples, one per ms")
    for name in ("regions", "Vec3 from regions", "elsewhere"):
        print(f"  {name}: {100.0 * shares[name] / total:.1f} %")
    for function, n in elsewhere.most_common(12):
        print(f"    {100.0 * n / total:4.1f} %  {function}")
    inside = shares["regions"] + shares["Vec3 from regions"]
    if inside:
        print(f"  at most {total / inside:.2f}x faster with nothing outside the regions")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("course_dir", nargs="?", help="checkout of the course's week-8 code")
    parser.add_argument("--width", type=int, default=64)
    parser.add_argument("--spp", type=int, default=2)
    parser.add_argument("--max-depth", type=int, default=5)
    parser.add_argument("--repeat", type=int, default=3, help="runs of each renderer")
    parser.add_argument(
        "--rtpy", action="append", default=[], metavar="DIR", help="another rtpy checkout to time"
    )
    parser.add_argument(
        "--shares", action="store_true", help="profile rtpy's render (py-spy): where time goes"
    )
    parser.add_argument("--child", choices=("course", "rtpy"), help=argparse.SUPPRESS)
    parser.add_argument("--renders", type=int, default=1, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child == "course":
        result = render_course(args.course_dir, args.width, args.spp, args.max_depth, seed=0)
    elif args.child == "rtpy":
        for _ in range(max(1, args.renders)):
            result = render_rtpy(args.width, args.spp, args.max_depth, seed=0)
    if args.child:
        print(json.dumps(result))
        return
    if args.shares:
        print_shares(args.width, args.spp, args.max_depth, max(1, args.repeat))
        return

    if not has_course(args.course_dir):
        print(f"no course checkout at {args.course_dir!r}: skipping the course's row")
    best = measure(
        args.course_dir, args.width, args.spp, args.max_depth, args.repeat, tuple(args.rtpy)
    )
    print(
        f"course's week-8 scene, width {args.width}, {args.spp} spp, max_depth {args.max_depth}, "
        f"best of {max(1, args.repeat)}:"
    )
    for label, r in best.items():
        line = (
            f"  {label}: {r['seconds']:.2f} s (CPU {r['cpu_seconds']:.2f} s), "
            f"{r['paths_per_second']:,.1f} paths/s"
        )
        if "course" in best and label != "course":
            ratio = r["paths_per_second"] / best["course"]["paths_per_second"]
            line += f", {ratio:.2f}x the course's"
        print(line)


if __name__ == "__main__":
    main()
