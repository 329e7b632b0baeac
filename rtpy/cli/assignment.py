"""The instructor's commands `assignment make WEEK OUT_DIR`, `assignment autograder WEEK
OUT.zip` and `assignment map-tests`: their options, the week and the outputs checked
before any work, a failing write reported in one line (exit 1). Not shipped in a
student repository (rtpy.grading.assignment INSTRUCTOR_MODULES), where the command
line has no `assignment`."""

from __future__ import annotations

import argparse
import sys

from ..engine.files import OutputError, WriteError
from .grade import WEEK_HELP, refused


def add_assignment_commands(sub, seconds) -> None:
    """The commands' parsers; `seconds` parses a number of seconds."""
    a = sub.add_parser("assignment", help="write a weekly assignment repository")
    asub = a.add_subparsers(dest="assignment_command", required=True, metavar="ACTION")
    make = asub.add_parser("make", help="write week WEEK's student repository to OUT_DIR")
    make.add_argument("week", metavar="WEEK", help=WEEK_HELP)
    make.add_argument("out_dir", metavar="OUT_DIR", help="a new or empty directory")
    z = asub.add_parser("autograder", help="write week WEEK's Gradescope autograder zip")
    z.add_argument("week", metavar="WEEK", help=WEEK_HELP)
    z.add_argument("out_zip", metavar="OUT.zip", help="the autograder to upload to Gradescope")
    from ..grading.autograder import TEST_TIMEOUT, TOTAL_TIMEOUT

    for option, default, what in (
        ("--test-timeout", TEST_TIMEOUT, "each test"),
        ("--total-timeout", TOTAL_TIMEOUT, "a whole submission"),
    ):
        z.add_argument(
            option, type=seconds, default=default, metavar="S", help=f"seconds for {what}"
        )
    m = asub.add_parser("map-tests", help="record which weeks each test file needs (slow)")
    m.add_argument("files", nargs="*", metavar="TEST_FILE", help="only these (tests/...)")


def command_assignment(args: argparse.Namespace) -> int:
    """Run `assignment ...`: 0 done, 1 a write failed, 2 a bad week or output (nothing
    written)."""
    from ..grading.assignment import AssignmentError, check_week, map_tests

    try:
        week = None if getattr(args, "week", None) is None else check_week(args.week)
        if args.assignment_command == "map-tests":
            weeks = map_tests(files=tuple(args.files))
            print(f"rtpy: {len(weeks)} test files need solution regions", file=sys.stderr)
            return 0
        what = "autograder" if args.assignment_command == "autograder" else "repository"
        written = write_assignment(args, week)
    except (WriteError, AssignmentError, OutputError, FileNotFoundError) as err:
        return refused(err)
    print(f"rtpy: wrote the week {week} {what} to {written}", file=sys.stderr)
    return 0


def write_assignment(args: argparse.Namespace, week: str):
    """`assignment make` or `assignment autograder`: the path written. An OSError
    while it is written (the disk full) is a WriteError naming the output."""
    from ..grading.assignment import make_assignment
    from ..grading.autograder import build_autograder

    autograder = args.assignment_command == "autograder"
    out = args.out_zip if autograder else args.out_dir
    try:
        if not autograder:
            return make_assignment(week, out)
        return build_autograder(
            week, out, test_timeout=args.test_timeout, total_timeout=args.total_timeout
        )
    except OSError as err:
        raise WriteError(out, err) from err
