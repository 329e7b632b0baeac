"""Command line: `python -m rtpy render SCENE ...` and `python -m rtpy scenes`; the
other commands are in rtpy.io.cli_assignment and rtpy.bench.command.

Exit status: 0 done, 1 the work failed: the worker processes (nothing is written) or
writing an output (disk full, file too large, I/O error: one line naming the file; an
output that was there is untouched), 2 bad input (scene file, option or output path;
nothing is written), 130 interrupted by Ctrl-C (SIGINT) and 143 by SIGTERM (the
passes finished are written first; rtpy.signals).
"""

from __future__ import annotations

import argparse
import sys
import tomllib
import warnings
from pathlib import Path

from ..render_settings import BACKENDS, SETTINGS, SettingError, unknown_setting
from ..signals import (
    NOTHING_WRITTEN,
    caused_by_interrupt,
    finishing,
    received,
    stop_on_signals,
    stopped,
)
from ..workers import WorkerError, available_cpus
from .cli_assignment import add_assignment_commands
from .image import OutputError, WriteError, check_image_path, check_linear_path
from .outputs import check_output

EXIT_WORKERS_FAILED = 1
EXIT_WRITE_FAILED = 1
EXIT_BAD_INPUT = 2


MAX_WORKERS = 256  # more processes than that only exhaust the machine


def seconds(text: str, zero: bool = False) -> float:
    """A number of seconds below 1e6: above 0, or from 0 with zero=True."""
    try:
        value = float(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a number of seconds, got {text!r}") from None
    if not ((value >= 0.0 if zero else value > 0.0) and value < 1e6):
        lowest = "from 0" if zero else "above 0"
        raise argparse.ArgumentTypeError(f"expected seconds {lowest}, got {text}")
    return value


def preview_seconds(text: str) -> float:
    """--preview-seconds: 0 (a preview after every unit of work) or more."""
    return seconds(text, zero=True)


def worker_count(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"expected a whole number, got {text!r}") from None
    if not 1 <= value <= MAX_WORKERS:
        raise argparse.ArgumentTypeError(f"expected 1 to {MAX_WORKERS} processes, got {value}")
    return value


def flag(name: str) -> str:
    """The option of a render setting that has a flag: max_depth -> --max-depth."""
    return "--" + name.replace("_", "-")


def add_setting_options(r: argparse.ArgumentParser) -> None:
    """--NAME for the render settings that have a flag, and --set KEY=VALUE for all
    of them (rtpy.render_settings.SETTINGS); the values are checked after parsing."""
    for name, setting in SETTINGS.items():
        if setting.flag:
            metavar = {"int": "N", "float": "X", "choice": "NAME"}.get(setting.kind)
            r.add_argument(flag(name), dest=name, metavar=metavar, help=setting.help)
    r.add_argument(
        "--set",
        action="append",
        default=[],
        metavar="KEY=VALUE",
        help=f"override a render setting, VALUE in TOML syntax ({', '.join(SETTINGS)})",
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
    r.add_argument("-q", "--quiet", action="store_true", help="no progress bar")
    r.add_argument(
        "--plugin",
        action="append",
        default=[],
        metavar="FILE.py",
        help="import FILE.py first (registers a student's materials by register_material)",
    )

    sub.add_parser("scenes", help="list the bundled scenes")
    if not every_command:
        return parser
    from ..bench.command import add_parser as add_bench_parser

    add_bench_parser(sub)
    add_assignment_commands(sub, seconds)
    return parser


def load_plugins(paths: list[str]) -> None:
    """Import each file (its @register_material classes become scene types)."""
    from ..plugins import PluginError, load_plugin

    for path in paths:
        try:
            load_plugin(path)
        except PluginError as err:
            raise UsageError(f"--plugin {err}") from None


class UsageError(Exception):
    pass


def shown(text: str) -> str:
    """text as a message shows it: as it is when printable, else quoted and escaped
    (a message stays one line)."""
    return text if text.isprintable() else repr(text)


def read_value(text: str, option: str):
    """A command-line value read as one TOML value (2, 2.5, true, [0.1, 0.2, 0.3],
    "path"), or the text itself when it is not TOML (a bare word such as srgb) or more
    than TOML takes (an integer of thousands of digits, arrays nested thousands deep).
    UsageError naming `option` for a line break (TOML reads the next line as more
    keys); a table is one value, refused by the setting's check as in a scene file."""
    if "\n" in text or "\r" in text:
        raise UsageError(f"{option}: expected one value on one line, got {text!r}")
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except (tomllib.TOMLDecodeError, ValueError, RecursionError):
        return text.strip()


def parse_set(items: list[str]) -> dict:
    """--set KEY=VALUE pairs -> {key: value}, values read as TOML."""
    result = {}
    for item in items:
        key, sep, text = item.partition("=")
        key = key.strip()
        if not sep:
            raise UsageError(f"--set {item!r}: expected KEY=VALUE")
        if key not in SETTINGS:
            error = unknown_setting(key, list(SETTINGS))
            raise UsageError(error.for_option(f"--set {shown(key)}"))
        result[key] = read_value(text, f"--set {key}")
    return result


def validate_overrides(overrides: dict, as_flags: bool = False) -> dict:
    """Check command-line overrides against their settings (as strictly as the scene
    file's own values); the values as rtpy uses them (background a Color)."""
    checked = {}
    for key, value in overrides.items():
        try:
            checked[key] = SETTINGS[key].check(value)
        except SettingError as e:
            option = flag(key) if as_flags else f"--set {key}"
            raise UsageError(e.for_option(option)) from None
    return checked


def check_width(scene, path: Path, overrides: dict, option: str) -> None:
    """A width override must give an image within the size limits with the scene's
    aspect ratio (checked before anything is allocated)."""
    if "width" not in overrides or scene.camera is None:
        return
    try:
        scene.camera.with_width(overrides["width"])
    except ValueError as e:
        raise UsageError(f"{option} {overrides['width']} with {path}'s aspect ratio: {e}") from None


def check_backend(name: str) -> None:
    """UsageError when the backend is withheld (the numpy backend in an assignment
    repository, whose stub says so in WITHHELD)."""
    if name != "numpy":
        return
    import rtpy.numpy_backend as backend

    withheld = getattr(backend, "WITHHELD", None)
    if withheld:
        raise UsageError(f"--backend numpy: {withheld}")


def command_scenes() -> int:
    from .bundled import bundled_scenes

    scenes = bundled_scenes()
    width = max((len(name) for name, _ in scenes), default=0)
    for name, description in scenes:
        print(f"{name:<{width}}  {description}")
    return 0


def command_render(args: argparse.Namespace) -> int:
    try:
        return _render(args)
    except BaseException as err:  # while loading, or before the render started
        if not caused_by_interrupt(err):
            raise
        return stopped(NOTHING_WRITTEN)


def check_outputs(args: argparse.Namespace, scene, path: Path) -> tuple:
    """(output, linear, preview) paths, each writable, none of them a file the render
    reads (the scene file, its images and meshes, the plugins) or another output."""
    inputs = [*scene.files, *args.plugin]
    output = check_output(
        args.output if args.output is not None else f"{path.stem}.png",
        "-o",
        inputs,
        check=check_image_path,
    )
    linear = preview = None
    if args.linear:
        linear = check_output(args.linear, "--linear", inputs, [output], check_linear_path)
    if args.preview:
        others = [output] + ([linear] if linear else [])
        preview = check_output(args.preview, "--preview", inputs, others, check_image_path)
    return output, linear, preview


def _render(args: argparse.Namespace) -> int:
    from .. import render
    from .bundled import resolve_scene
    from .scene_file import SceneError, SceneWarning, load_scene

    try:
        load_plugins(args.plugin)
        path = resolve_scene(args.scene)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", SceneWarning)
            scene = load_scene(path)
        for warning in caught:  # one line each, as errors are
            print(f"rtpy: warning: {warning.message}", file=sys.stderr)
        overrides = validate_overrides(parse_set(args.set))
        flags = {name: getattr(args, name) for name, setting in SETTINGS.items() if setting.flag}
        given = {k: read_value(v, flag(k)) for k, v in flags.items() if v is not None}
        overrides.update(validate_overrides(given, as_flags=True))
        check_width(scene, path, overrides, "--width" if args.width is not None else "--set width")
        output, linear, preview = check_outputs(args, scene, path)
        check_backend(args.backend)
    except (SceneError, OutputError, UsageError) as err:
        print(f"rtpy: error: {err}", file=sys.stderr)
        return EXIT_BAD_INPUT

    try:
        image = render(
            scene,
            workers=args.workers,
            quiet=args.quiet,
            backend=args.backend,
            preview=preview,
            preview_seconds=args.preview_seconds,
            **overrides,
        )
    except WorkerError as err:
        if received() is not None:  # the signal ended the workers too
            raise KeyboardInterrupt from None
        print(f"rtpy: error: {err}", file=sys.stderr)
        return EXIT_WORKERS_FAILED
    except WriteError as err:  # a preview
        print(f"rtpy: error: {err}", file=sys.stderr)
        return EXIT_WRITE_FAILED
    if image.interrupted and image.samples_min == 0:
        return stopped("interrupted before a pass over the image finished: nothing was written")
    if image.interrupted:
        print(
            "rtpy: interrupted: writing the samples finished so far "
            "(Ctrl-C again stops at once, writing nothing)",
            file=sys.stderr,
            flush=True,
        )

    # The image in hand is written whole, even after a signal (a second one ends at
    # once, leaving no file half-written: rtpy.signals).
    try:
        with finishing():
            written = [image.save(path) for path in (output, linear) if path is not None]
    except WriteError as err:
        print(f"rtpy: error: {err}", file=sys.stderr)
        return EXIT_WRITE_FAILED
    stats = image.stats
    files = ", ".join(str(p) for p in written)
    if image.interrupted:
        return stopped(
            f"interrupted: wrote {files} holding {image.samples_min}-{image.samples_max} "
            f"of {image.spp} samples per pixel"
        )
    if received() is not None:  # while writing the finished image
        return stopped(f"interrupted while writing: wrote {files}, complete")
    print(
        f"rtpy: wrote {files}: {image.width}x{image.height}, {image.spp} spp, "
        f"{stats['seconds']:.2f} s, {stats['paths_per_second']:,.0f} paths/s",
        file=sys.stderr,
    )
    return 0


def main(argv: list[str] | None = None, prog: str = "rtpy") -> int:
    """Run the command line `argv` (default sys.argv[1:]); `prog` names the program in
    usage lines and errors (`python -m rtpy` passes its own). Returns the exit status.
    SIGINT and SIGTERM stop the command (rtpy.signals)."""
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
        from ..bench.command import command_bench

        return command_bench(args)
    if args.command in ("assignment", "grade"):
        from .cli_assignment import command_assignment

        return command_assignment(args)
    return command_render(args)


if __name__ == "__main__":
    sys.exit(main())
