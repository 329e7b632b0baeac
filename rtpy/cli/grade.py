"""The command `grade WEEK`: run a week's graders and print the score (the week is
checked before any work, a failing write reported in one line)."""

from __future__ import annotations

import argparse
import sys

from ..engine.exit_status import EXIT_BAD_INPUT, EXIT_WRITE_FAILED
from ..engine.files import OutputError, WriteError, check_writable

WEEK_HELP = "the week's two digits, 03 to 08"


def add_grade_command(sub) -> None:
    """The `grade` command's parser."""
    g = sub.add_parser("grade", help="run a week's graders and print the score")
    g.add_argument("week", metavar="WEEK", help=WEEK_HELP)
    g.add_argument("--json", metavar="RESULTS.json", help="Gradescope results file")
    g.add_argument(
        "--hidden", action="store_true", help="also the hidden checks (rtpy's own repository)"
    )


def command_grade(args: argparse.Namespace) -> int:
    """0 when every grader passes, 1 otherwise (or a write failed), 2 a bad week or
    output (nothing written)."""
    from ..grading.weeks import AssignmentError, check_week

    try:
        week = check_week(args.week)
        if args.json:
            check_writable(args.json)
        return grade_week(week, args.json, args.hidden)
    except (WriteError, AssignmentError, OutputError, FileNotFoundError) as err:
        return refused(err)


def refused(err: Exception) -> int:
    """Say err in one line; the exit status: a failed write 1, anything else 2."""
    print(f"rtpy: error: {err}", file=sys.stderr)
    return EXIT_WRITE_FAILED if isinstance(err, WriteError) else EXIT_BAD_INPUT


def grade_week(week: str, json_path: str | None, hidden: bool = False) -> int:
    """0 when every grader passes, 1 otherwise."""
    from ..grading.graders import grade
    from ..grading.results import score_table, write_results

    results = grade(week, hidden=hidden)
    print(score_table(results))
    if json_path:
        write_results(json_path, results)
    passed = bool(results["tests"]) and results["score"] == results["max_score"]
    return 0 if passed else 1
