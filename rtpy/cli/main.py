"""Command line: `python -m rtpy render SCENE ...` and `python -m rtpy scenes`; the
other commands are in rtpy.cli.grade, rtpy.cli.bench.command and, in the instructor's
install only, rtpy.cli.assignment.

The values of a render are checked once, by rtpy.render's boundary
(rtpy.engine.render_request.prepare_render): the command line reads them (TOML values of
--set and the flags) and names the option in the one line of an error. Exit
statuses: rtpy.engine.exit_status (0 done, 1 the workers or a write failed, 2 bad input,
130 and 143 after SIGINT and SIGTERM, the whole passes written first).
"""

from __future__ import annotations

import argparse
import sys
import warnings
from importlib.util import find_spec
from pathlib import Path

from .._checks import one_line
from ..engine.backends import BACKENDS
from ..engine.exit_status import EXIT_BAD_INPUT, EXIT_WORKERS_FAILED, EXIT_WRITE_FAILED
from ..engine.files import OutputError, WriteError
from ..engine.signals import (
    NOTHING_WRITTEN,
    caused_by_interrupt,
    finishing,
    received,
    stop_on_signals,
    stopped,
)
from ..engine.unfinished import stub_message
from ..engine.workers import WorkerError, available_cpus
from ..io.image import check_image_path, check_linear_path, write_image
from ..io.outputs import check_output
from ..render_settings import SettingError
from .grade import add_grade_command, command_grade
from .options import (
    MAX_WORKERS,
    UsageError,
    add_setting_options,
    check_backend,
    given_settings,
    preview_seconds,
    seconds,
    worker_count,
)


class _Version(argparse.Action):
    """--version: the installed version, looked up only when asked for."""

    def __call__(self, parser, namespace, values, option_string=None) -> None:
        from .. import __version__

        print(f"{parser.prog} {__version__}")
        parser.exit()


def build_parser(prog: str = "rtpy", every_command: bool = True) -> argparse.ArgumentParser:
    """The command line's parser; `prog` is the program as it was run (usage lines and
    argparse's errors name it). every_command=False leaves out the bench and
    assignment commands, whose options import their modules (a render starts sooner)."""
    parser = argparse.ArgumentParser(
        prog=prog,
        description="rtpy: a teaching ray tracer in Python.",
        epilog=f"'{prog} COMMAND --help' shows a command's options.",
    )
    parser.add_argument("--version", action=_Version, nargs=0, help="show the version and exit")
    sub = parser.add_subparsers(dest="command", required=True, metavar="COMMAND")
    add_render_parser(sub)
    sub.add_parser("scenes", help="list the bundled scenes")
    if not every_command:
        return parser
    from .bench.command import add_parser as add_bench_parser

    add_bench_parser(sub)
    add_grade_command(sub)
    if find_spec(f"{__package__}.assignment") is not None:  # the instructor's install only
        from .assignment import add_assignment_commands

        add_assignment_commands(sub, seconds)
    from .ladder import add_ladder_parser

    add_ladder_parser(sub)
    return parser


def add_render_parser(sub) -> None:
    """The `render` command and its options."""
    r = sub.add_parser(
        "render",
        help="render a scene file to an image",
        description="Render SCENE (a .toml path or a bundled scene's name) to a PNG.",
    )
    r.add_argument("scene", metavar="SCENE", help="scene file, or the name of a bundled scene")
    r.add_argument(
        "-o",
        "--output",
        metavar="OUT.png",
        help="8-bit image (.png/.jpg), gamma-encoded; default SCENE_NAME.png",
    )
    r.add_argument(
        "--linear",
        metavar="OUT.npy|OUT.pfm|OUT.exr",
        help="also write the linear float image: .npy, .pfm or .exr (never gamma-encoded)",
    )
    r.add_argument(
        "--preview",
        metavar="PREVIEW.png",
        help="while rendering, rewrite this 8-bit image with the samples finished so far",
    )
    r.add_argument(
        "--preview-seconds",
        type=preview_seconds,
        default=5.0,
        metavar="S",
        help="at most one preview every S seconds (default 5)",
    )
    add_setting_options(r)
    cpus = min(available_cpus(), MAX_WORKERS)
    r.add_argument(
        "-j",
        "--workers",
        type=worker_count,
        default=cpus,
        metavar="N",
        help=f"processes (default {cpus}: the CPUs this process may use; at most {MAX_WORKERS})",
    )
    r.add_argument(
        "--backend",
        choices=BACKENDS,
        default="scalar",
        help="scalar: the readable reference (default); numpy: vectorized, many times faster",
    )
    r.add_argument(
        "--time",
        dest="time_limit",
        metavar="SECONDS",
        help="render whole passes until SECONDS are spent (at least one; --spp the most)",
    )
    r.add_argument(
        "--resume",
        action="store_true",
        help="continue the render stopped with these outputs (its state: OUT.png.resume.npz)",
    )
    r.add_argument(
        "--cluster",
        metavar="ADDRESS",
        help="render on Dask distributed: a scheduler's tcp://host:8786, or local "
        "(a local cluster of -j workers); pip install 'rtpy[cluster]'",
    )
    r.add_argument(
        "--cluster-timeout",
        type=seconds,
        metavar="SECONDS",
        help="how long to try to reach the --cluster scheduler (default 5)",
    )
    r.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    r.add_argument(
        "--plugin",
        action="append",
        default=[],
        metavar="FILE.py",
        help="import FILE.py first (registers a student's materials by register_material)",
    )


def load_plugins(paths: list[str]) -> None:
    """Import each file (its @register_material classes become scene types)."""
    from ..engine.plugins import PluginError, load_plugin

    for path in paths:
        try:
            load_plugin(path)
        except PluginError as err:
            raise UsageError(f"--plugin {err}") from None


def prepare(args: argparse.Namespace, scene, path: Path, given: dict, preview, state):
    """The Renderer of the command, its values checked by rtpy.render's boundary;
    UsageError naming the option of a value it refuses."""
    from ..engine.render_request import AspectError, prepare_render

    def write_preview(image) -> None:
        write_image(preview, image.linear, image.gamma)

    try:
        return prepare_render(
            scene,
            workers=args.workers,
            quiet=args.quiet,
            backend=args.backend,
            preview=write_preview if preview is not None else None,
            preview_seconds=args.preview_seconds,
            cluster=args.cluster,
            cluster_timeout=args.cluster_timeout,
            checkpoint=state,
            resume=args.resume,
            **{key: value for key, (_, value) in given.items()},
        )
    except AspectError as e:
        option = given["width"][0]
        raise UsageError(f"{option} {e.width} with {path}'s aspect ratio: {e.reason}") from None
    except SettingError as e:
        raise UsageError(e.for_option(given.get(e.key, (f"--set {e.key}",))[0])) from None
    except (TypeError, ValueError) as e:
        if str(e).startswith("cluster: "):  # the only other value the command passes on
            raise UsageError(f"--cluster {args.cluster}: {str(e)[len('cluster: ') :]}") from None
        raise


def command_scenes() -> int:
    from ..io.bundled import bundled_scenes

    scenes = bundled_scenes()
    width = max((len(name) for name, _ in scenes), default=0)
    for name, description in scenes:
        print(f"{name:<{width}}  {description}")
    return 0


def command_render(args: argparse.Namespace) -> int:
    try:
        return _render(args)
    except BaseException as err:  # while loading, or before the render started
        if caused_by_interrupt(err):
            return stopped(NOTHING_WRITTEN)
        if (line := stub_message(err) if isinstance(err, Exception) else None) is None:
            raise
        print(f"rtpy: error: {line}", file=sys.stderr)  # a task not written yet
        return EXIT_BAD_INPUT


def check_outputs(args: argparse.Namespace, scene, path: Path) -> tuple:
    """(output, linear, preview, state) paths, each writable, none of them a file the
    render reads (the scene file, its images and meshes, the plugins) or another
    output; state is where the render is kept to be resumed, beside the output."""
    from ..engine.render_state import state_path

    inputs = [*scene.files, *args.plugin]
    output = check_output(
        args.output if args.output is not None else f"{path.stem}.png",
        "-o",
        inputs,
        check=check_image_path,
    )
    linear = preview = None
    if args.linear is not None:  # '' is refused as -o '' is
        linear = check_output(args.linear, "--linear", inputs, [output], check_linear_path)
    if args.preview is not None:
        others = [output] + ([linear] if linear else [])
        preview = check_output(args.preview, "--preview", inputs, others, check_image_path)
    others = [p for p in (output, linear, preview) if p is not None]
    state = check_output(state_path(output), "-o", inputs, others)
    return output, linear, preview, state


def _render(args: argparse.Namespace) -> int:
    from ..engine.render_state import ResumeError
    from ..io.bundled import resolve_scene
    from ..io.scene_file import SceneError, SceneWarning, load_scene

    try:
        load_plugins(args.plugin)
        path = resolve_scene(args.scene)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", SceneWarning)
            scene = load_scene(path)
        for warning in caught:  # one line each, as errors are
            print(f"rtpy: warning: {one_line(str(warning.message))}", file=sys.stderr)
        given = given_settings(args)
        output, linear, preview, state = check_outputs(args, scene, path)
        check_backend(args.backend)
        renderer = prepare(args, scene, path, given, preview, state)
    except (SceneError, OutputError, UsageError) as err:
        print(f"rtpy: error: {one_line(str(err))}", file=sys.stderr)
        return EXIT_BAD_INPUT
    if state.exists() and not args.resume:
        print(
            f"rtpy: note: starting over; --resume continues the render in {state}", file=sys.stderr
        )
    elif args.resume and not state.exists():
        print(f"rtpy: note: --resume: no saved render ({state}): starting from the beginning",
              file=sys.stderr)  # fmt: skip

    kept = state.exists()
    try:
        image = renderer.render(then_write=True)  # a signal from its end on: written
    except NotImplementedError as err:  # a task not written yet (rtpy.engine.unfinished)
        if (line := stub_message(err, renderer, "--integrator {}")) is None:
            raise
        if not kept:  # the passes before it: nothing to resume once the task is written
            state.unlink(missing_ok=True)
        print(f"rtpy: error: {line}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except ResumeError as err:
        print(
            f"rtpy: error: --resume: {one_line(str(err))}; render without --resume to start over",
            file=sys.stderr,
        )
        return EXIT_BAD_INPUT
    except WorkerError as err:
        if received() is not None:  # the signal ended the workers too
            raise KeyboardInterrupt from None
        print(f"rtpy: error: {one_line(str(err))}", file=sys.stderr)
        return EXIT_WORKERS_FAILED
    except WriteError as err:  # a preview, or the render's state
        kept = f"; --resume continues the render ({state})" if renderer.saved else ""
        print(f"rtpy: error: {one_line(str(err))}{one_line(kept)}", file=sys.stderr)
        return EXIT_WRITE_FAILED
    return write_outputs(image, [p for p in (output, linear) if p is not None], renderer)


def write_outputs(image, outputs: list[Path], renderer) -> int:
    """Write the image of a render, finished or stopped, and say what it holds."""
    stopped_by = image.stats["stopped"]
    kept = ""
    if stopped_by and image.stats["checkpoint_saved"]:
        kept = f"; --resume continues it ({renderer.checkpoint.path})"
    if stopped_by == "interrupted" and image.samples_min == 0:
        if kept:
            return stopped(f"interrupted before a pass over the image finished: no image{kept}")
        return stopped("interrupted before a pass over the image finished: nothing was written")
    if stopped_by == "interrupted":
        print(
            "rtpy: interrupted: writing the samples finished so far "
            "(Ctrl-C again stops at once, writing nothing)",
            file=sys.stderr,
            flush=True,
        )
    # The image in hand is written whole, even after a signal (a second one ends at
    # once, leaving no file half-written: rtpy.engine.signals).
    try:
        with finishing():
            written = [write_image(p, image.linear, image.gamma) for p in outputs]
    except WriteError as err:
        print(f"rtpy: error: {one_line(str(err))}", file=sys.stderr)
        return EXIT_WRITE_FAILED
    files = ", ".join(str(p) for p in written)
    if stopped_by == "interrupted":
        return stopped(
            f"interrupted: wrote {files} holding {image.samples_min} of {image.spp} samples "
            f"per pixel{kept}"
        )
    if stopped_by is None:
        renderer.checkpoint.remove()
    if received() is not None:  # while writing the image
        return stopped(f"interrupted while writing: wrote {files}{kept or ', complete'}")
    stats, resumed = image.stats, image.stats["resumed_samples"]
    samples = (
        f"{image.spp} spp" if stopped_by is None else f"{image.samples_min} of {image.spp} spp"
    )
    if stopped_by:
        samples += f" in the time limit of {renderer.time_limit:g} s"
    if resumed:
        samples += f" ({resumed} resumed)"
    print(
        f"rtpy: wrote {files}: {image.width}x{image.height}, {samples}, "
        f"{stats['seconds']:.2f} s, {stats['paths_per_second']:,.0f} paths/s{kept}",
        file=sys.stderr,
    )
    return 0


def main(argv: list[str] | None = None, prog: str = "rtpy") -> int:
    """Run the command line `argv` (default sys.argv[1:]); `prog` names the program in
    usage lines and errors (`python -m rtpy` passes its own). Returns the exit status.
    SIGINT and SIGTERM stop the command (rtpy.engine.signals)."""
    argv = sys.argv[1:] if argv is None else argv
    parser = build_parser(prog, every_command=argv[:1] not in (["render"], ["scenes"]))
    if not argv:
        parser.print_help()
        return 0
    args = parser.parse_args(argv)  # usage errors exit with status 2
    try:
        with stop_on_signals():
            return _run_command(args)
    except Exception as err:
        if not caused_by_interrupt(err):
            raise
        return stopped("interrupted")
    except KeyboardInterrupt:  # in a command that does not handle it
        return stopped(NOTHING_WRITTEN if args.command in ("render", "scenes") else "interrupted")


def _run_command(args: argparse.Namespace) -> int:
    """Run the command `args` holds (parsed by build_parser's parser)."""
    if args.command == "scenes":
        return command_scenes()
    if args.command == "bench":
        from .bench.command import command_bench

        return command_bench(args)
    if args.command == "ladder":
        from .ladder import command_ladder

        return command_ladder(args)
    if args.command == "grade":
        return command_grade(args)
    if args.command == "assignment":
        from .assignment import command_assignment

        return command_assignment(args)
    return command_render(args)


if __name__ == "__main__":
    sys.exit(main())


def console() -> int:
    """The `rtpy` console script: a process of rtpy's own, its memory tuned as
    `python -m rtpy` tunes it (rtpy.engine.memory); main() called from Python is not."""
    from ..engine import memory

    memory.small_pages_for_numpy()
    memory.tune_for_large_scenes()
    return main()
