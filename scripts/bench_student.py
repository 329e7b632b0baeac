"""How long a student's week-8 submission render takes, and where its time goes.

    python scripts/bench_student.py [COURSE_DIR] [--spp 128] [--course-spp 16]
                                    [--profile-spp 2] [--workers 2] [--skip-full]
                                    [--skip-command] [--rtpy-spp N] [--weeks]

The submission render of week 8 (assignments/week08/README.md): 480x270, 128 samples
per pixel, max depth 5, the `path` integrator, the scalar backend (the student's own
code), two worker processes. In one run this script times, each in a fresh process:

1. the command a student types, on the bundled week-8 Phong scene:
   `python -m rtpy render week08_phong --width 480 --spp 128 --max-depth 5
   --integrator path --backend scalar -j 2`, wall-clock seconds from the command's
   start to its exit (imports and writing the PNG included) and CPU seconds;
2. rtpy on the course's own week-8 scene (scripts/bench_course.py builds it in code
   for both renderers), the same settings, rtpy.render(workers=2);
3. the course's own week-8 code (COURSE_DIR, a checkout of
   KUGA-01418283-Raytracing/RT-python-week08, kept outside this repository) on that
   scene: its renderer has one process. It renders --course-spp samples per pixel
   and the time is scaled to --spp linearly (rendering time is proportional to the
   samples: the script prints both); without COURSE_DIR this row is skipped.

Then it profiles rtpy's render of week08_phong in this process (--profile-spp, one
process) by sampling the main thread's stack every millisecond, and shares the
samples out by the course's parts: intersection, light sampling, materials,
integrator, camera, sampler, pixel sums (a sample is charged to the innermost
frame of those parts; the utilities, Vec3, Ray, HitInfo, intervals, to their
caller; the sampling slows the render, not the shares). Process overhead is row
1's wall clock minus its CPU seconds over the workers: the time the processes are
not all busy (start-up, the workers' start, the last units, writing the PNG) and
the time other programs take the CPUs from them.

The full render takes minutes: run it at low priority, `nice -n 10 python ...`.
--skip-full leaves out rows 1 and 2 (the profile and the course only), --skip-command
row 1; --rtpy-spp renders row 2 at fewer spp, scaled to --spp as the course's row.

--weeks instead times the render list of every week (assignments/weekNN/tasks.toml)
as submitted (480 wide, max depth 5, the scene's integrator), each scene at 2 and 8
spp, and extrapolates to --spp on --workers idle cores: the CPU seconds fitted as
a + b spp, the time as a + b spp / workers. The week READMEs state the largest of
each week (tasks.toml's render_time).
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
import tempfile
import threading
import time
from collections import Counter
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))
import bench_course  # noqa: E402

ROOT = Path(__file__).resolve().parents[1]
WIDTH, MAX_DEPTH = 480, 5
SCENE = "week08_phong"

# rtpy file (from rtpy/) -> the part of the course it belongs to; a folder ends in "/".
PARTS = {
    "sphere.py": "intersection",
    "quad.py": "intersection",
    "triangle.py": "intersection",
    "mesh.py": "intersection",
    "bvh.py": "intersection",
    "scene.py": "intersection",
    "hittable.py": "intersection",
    "light.py": "light sampling",
    "integrators/direct_lighting.py": "light sampling",
    "materials/": "materials",
    "texture.py": "materials",
    "integrators/": "integrator",
    "environment.py": "integrator",
    "camera.py": "camera",
    "sampler.py": "sampler",
    "sampling.py": "sampler",
    "engine/scalar_backend.py": "pixel sums",
    "engine/pixel_sums.py": "pixel sums",
}
ORDER = [
    "intersection",
    "light sampling",
    "materials",
    "integrator",
    "camera",
    "sampler",
    "pixel sums",
    "other",
]


def part_of(filename: str) -> str | None:
    """The part a file of rtpy belongs to, None for the utilities and other files."""
    name = filename.replace("\\", "/")
    if "/rtpy/" not in name:
        return None
    rel = name.rpartition("/rtpy/")[2]
    hits = [p for p in PARTS if rel == p or (p.endswith("/") and rel.startswith(p))]
    return PARTS[max(hits, key=len)] if hits else None


def charge(frame) -> str:
    """The part a stack sample is charged to: its innermost frame in one of PARTS."""
    while frame is not None:
        part = part_of(frame.f_code.co_filename)
        if part is not None:
            return part
        frame = frame.f_back
    return "other"


def profile(spp: int) -> tuple[Counter, float, int]:
    """Render week08_phong in this process, sampling the stack every millisecond:
    (samples per part, seconds of the render, paths)."""
    import rtpy

    scene = rtpy.load_scene(SCENE)
    main = threading.main_thread().ident
    counts: Counter = Counter()
    done = threading.Event()

    def sample() -> None:
        while not done.wait(0.001):
            frame = sys._current_frames().get(main)
            if frame is not None:
                counts[charge(frame)] += 1

    sys.setswitchinterval(0.0005)  # the sampler gets the interpreter every 0.5 ms
    thread = threading.Thread(target=sample, daemon=True)
    thread.start()
    image = rtpy.render(
        scene, width=WIDTH, spp=spp, max_depth=MAX_DEPTH, integrator="path", workers=1
    )
    done.set()
    thread.join()
    return counts, image.stats["seconds"], image.width * image.height * spp


def time_command(spp: int, workers: int, scene: str = SCENE, integrator="path") -> dict:
    """The student's command, timed from start to exit (`integrator` None: the scene's)."""
    with tempfile.TemporaryDirectory() as tmp:
        command = [sys.executable, "-m", "rtpy", "render", scene, "--width", str(WIDTH)]
        command += ["--spp", str(spp), "--max-depth", str(MAX_DEPTH)]
        command += ["--integrator", integrator] if integrator else []
        command += ["--backend", "scalar", "-j", str(workers), "-q", "-o", f"{tmp}/out.png"]
        before = os.times()
        wall = time.perf_counter()
        subprocess.run(command, check=True, cwd=ROOT, capture_output=True)
        wall = time.perf_counter() - wall
        after = os.times()
    cpu = (after.children_user - before.children_user) + (
        after.children_system - before.children_system
    )
    return {"seconds": wall, "cpu_seconds": cpu, "paths": WIDTH * (WIDTH * 9 // 16) * spp}


def child(kind: str, spp: int, workers: int, course_dir: str | None) -> dict:
    """Row 2 or 3 in a fresh process (this script with --child)."""
    command = [sys.executable, __file__, "--child", kind, "--spp", str(spp)]
    command += ["--workers", str(workers)] + ([course_dir] if course_dir else [])
    out = subprocess.run(command, check=True, capture_output=True, text=True, cwd=ROOT)
    return json.loads(out.stdout.strip().splitlines()[-1])


def minutes(seconds: float) -> str:
    return (
        f"{int(seconds // 60)} min {seconds % 60:04.1f} s" if seconds >= 60 else f"{seconds:.1f} s"
    )


def print_profile(spp: int, full_spp: int, command: dict | None, workers: int) -> None:
    counts, seconds, paths = profile(spp)
    total = sum(counts.values()) or 1
    print(
        f"\nwhere the time goes: {SCENE}, {WIDTH} wide, {spp} spp, one process, "
        f"{seconds:.1f} s, {paths / seconds:,.0f} paths/s ({total} stack samples)"
    )
    rows = [(part, counts[part] / total) for part in ORDER]
    if command is not None:
        busy = command["cpu_seconds"] / workers  # the seconds both processes were busy
        share = max(0.0, 1.0 - busy / command["seconds"])
        rows = [(part, f * (1.0 - share)) for part, f in rows] + [("process overhead", share)]
        print(
            f"shares of the {full_spp}-spp command's {minutes(command['seconds'])}: process "
            f"overhead is the wall clock minus its CPU time over {workers} workers"
        )
    print("| part | share |\n|---|---|")
    for part, f in rows:
        print(f"| {part} | {100.0 * f:.0f} % |")


def week_times(spp: int, workers: int, low: tuple[int, int] = (2, 8)) -> None:
    """Each week's submission render, per scene of its render list: the command at two
    low spp, its CPU seconds fitted as a + b spp and the time on `workers` idle cores
    extrapolated to `spp` as a + b spp / workers (a: start-up and writing, one process)."""
    from rtpy.grading.tasks import load_weeks

    print(f"| week | scene | CPU s at {low[0]} / {low[1]} spp | {spp} spp on {workers} cores |")
    print("|---|---|---|---|")
    for week in load_weeks(ROOT):
        for render in {r.scene: r for r in week.renders}.values():  # each scene once
            scene = render.scene
            if scene.endswith(".toml"):
                scene = f"assignments/week{week.week}/{scene}"
            cpu = [time_command(n, workers, scene, None)["cpu_seconds"] for n in low]
            b = max(0.0, (cpu[1] - cpu[0]) / (low[1] - low[0]))
            a = max(0.0, cpu[0] - b * low[0])
            estimate = a + b * spp / workers
            print(f"| {week.week} | {render.scene} | {cpu[0]:.1f} / {cpu[1]:.1f} | "
                  f"{minutes(estimate)} |", flush=True)  # fmt: skip


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("course_dir", nargs="?", help="checkout of the course's week-8 code")
    parser.add_argument("--spp", type=int, default=128)
    parser.add_argument("--course-spp", type=int, default=16)
    parser.add_argument("--profile-spp", type=int, default=2)
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--skip-full", action="store_true", help="profile and course only")
    parser.add_argument("--skip-command", action="store_true", help="leave out row 1")
    parser.add_argument("--rtpy-spp", type=int, default=0, help="row 2's spp (scaled to --spp)")
    parser.add_argument(
        "--weeks", action="store_true", help="every week's renders, extrapolated from low spp"
    )
    parser.add_argument("--child", choices=("course", "rtpy"), help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.child == "course":
        r = bench_course.render_course(args.course_dir, WIDTH, args.spp, MAX_DEPTH, seed=0)
        print(json.dumps(r))
        return
    if args.child == "rtpy":
        before = os.times()
        r = bench_course.render_rtpy(WIDTH, args.spp, MAX_DEPTH, seed=0, workers=args.workers)
        after = os.times()  # the workers' CPU time too
        r["cpu_seconds"] += after.children_user - before.children_user
        r["cpu_seconds"] += after.children_system - before.children_system
        print(json.dumps(r))
        return

    if args.weeks:
        week_times(args.spp, args.workers)
        return
    print(
        f"week-8 submission render: {WIDTH}x{WIDTH * 9 // 16}, {args.spp} spp, max depth "
        f"{MAX_DEPTH}, path, scalar, {args.workers} workers; {os.cpu_count()} CPUs here"
    )
    print("| render | wall clock | CPU | paths per CPU second |\n|---|---|---|---|")
    command = None
    if not args.skip_full and not args.skip_command:
        command = time_command(args.spp, args.workers)
        print_row(f"`rtpy render {SCENE}` (the command)", command)
    if not args.skip_full:
        rtpy_spp = args.rtpy_spp or args.spp
        r = scaled(child("rtpy", rtpy_spp, args.workers, None), args.spp / rtpy_spp)
        print_row(f"rtpy on the course's scene, {args.workers} workers{r['label']}", r)
    if bench_course.has_course(args.course_dir):
        r = scaled(child("course", args.course_spp, 1, args.course_dir), args.spp / args.course_spp)
        print_row(f"the course's code, one process{r['label']}", r)
    else:
        print(f"(no course checkout at {args.course_dir!r}: the course's row is skipped)")
    print_profile(args.profile_spp, args.spp, command, args.workers)


def scaled(r: dict, scale: float) -> dict:
    """A render's times and paths scaled from the spp it rendered to the row's."""
    if scale == 1:
        return {**r, "label": ""}
    out = {k: r[k] * scale for k in ("seconds", "cpu_seconds", "paths")}
    return {**out, "label": f" ({r['paths'] / (WIDTH * (WIDTH * 9 // 16)):g} spp x {scale:g})"}


def print_row(label: str, r: dict) -> None:
    rate = r["paths"] / r["cpu_seconds"] if r["cpu_seconds"] else float("nan")
    print(
        f"| {label} | {minutes(r['seconds'])} | {minutes(r['cpu_seconds'])} | {rate:,.0f} |",
        flush=True,
    )


if __name__ == "__main__":
    main()
