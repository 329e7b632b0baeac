"""The command `python -m rtpy ladder SCENE -o OUT.png`: the scene on every rung of the
lecture's ladder (rtpy.io.ladder) as one labelled strip. Every value is checked
before the first render; a bad one is refused in one line, exit status 2, nothing
written."""

from __future__ import annotations

import argparse
import sys

from ..engine.backends import BACKENDS
from ..engine.exit_status import EXIT_BAD_INPUT, EXIT_WORKERS_FAILED, EXIT_WRITE_FAILED
from ..engine.files import OutputError, WriteError
from ..engine.signals import NOTHING_WRITTEN, received, stopped
from ..engine.workers import WorkerError, available_cpus
from ..io.image import check_image_path
from ..io.outputs import check_output
from ..render_settings import SettingError
from .options import (
    MAX_WORKERS,
    UsageError,
    add_setting_options,
    check_backend,
    given_settings,
    worker_count,
)


def add_ladder_parser(sub) -> None:
    """The `ladder` command and its options (the render settings but the integrator)."""
    p = sub.add_parser(
        "ladder",
        help="render a scene on every rung of the lecture's ladder, as one labelled strip",
        description="Render SCENE with colour, shading without and with shadows, Whitted "
        "and path tracing, side by side in one labelled PNG.",
    )
    p.add_argument("scene", metavar="SCENE", help="scene file, or the name of a bundled scene")
    p.add_argument(
        "-o", "--output", metavar="OUT.png", help="the strip (.png/.jpg); default SCENE_ladder.png"
    )
    add_setting_options(p, hidden=("integrator",))  # each rung sets it
    p.set_defaults(time_limit=None)  # no --time: a limit per rung is --set time_limit=S
    cpus = min(available_cpus(), MAX_WORKERS)
    p.add_argument(
        "-j", "--workers", type=worker_count, default=cpus, metavar="N", help=f"default {cpus}"
    )
    p.add_argument("--backend", choices=BACKENDS, default="scalar", help="numpy: many times faster")
    p.add_argument("-q", "--quiet", action="store_true", help="no progress bars")


def _checked(args: argparse.Namespace):
    """(scene, output path, settings): UsageError, SceneError or OutputError first."""
    from .. import load_scene
    from ..io.bundled import resolve_scene
    from ..io.ladder import CHOSEN

    given = given_settings(args)
    for key in CHOSEN:
        if key in given:
            raise UsageError(f"{given[key][0]}: the ladder sets it on each rung; leave it out")
    path = resolve_scene(args.scene)
    scene = load_scene(path)
    default = f"{path.stem}_ladder.png"
    output = check_output(args.output or default, "-o", scene.files, check=check_image_path)
    check_backend(args.backend)
    return scene, output, given


def command_ladder(args: argparse.Namespace) -> int:
    """Render the rungs and write the strip: 0 done, 1 the workers or the write failed,
    2 bad input (nothing written), 130/143 after SIGINT/SIGTERM (nothing written)."""
    from ..io.ladder import RUNGS, ladder, write_ladder
    from ..io.scene_file import SceneError

    try:
        scene, output, given = _checked(args)
        settings = {key: value for key, (_, value) in given.items()}
        options = {"backend": args.backend, "workers": args.workers, "quiet": args.quiet}
        images = ladder(scene, **options, **settings)
    except (SceneError, OutputError, UsageError) as err:
        print(f"rtpy: error: {err}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except SettingError as err:  # refused by the first rung, before it rendered
        print(
            f"rtpy: error: {err.for_option(given.get(err.key, ('--set ' + err.key,))[0])}",
            file=sys.stderr,
        )
        return EXIT_BAD_INPUT
    except WorkerError as err:
        if received() is not None:
            return stopped(NOTHING_WRITTEN)
        print(f"rtpy: error: {err}", file=sys.stderr)
        return EXIT_WORKERS_FAILED
    if len(images) < len(RUNGS) or images[-1].interrupted:
        return stopped(NOTHING_WRITTEN)
    try:
        written = write_ladder(output, images)
    except WriteError as err:
        print(f"rtpy: error: {err}", file=sys.stderr)
        return EXIT_WRITE_FAILED
    seconds = sum(image.stats.get("seconds", 0.0) for image in images)
    print(f"rtpy: wrote {written}: {len(images)} rungs, {seconds:.1f} s", file=sys.stderr)
    return 0
