"""The course's weeks: which there are, and a week as the command line names it.

Shared by `rtpy grade` (in every student repository) and by the instructor's
assignment authoring (rtpy.grading.assignment), which is not shipped to students.
"""

from __future__ import annotations

__all__ = ["WEEKS", "AssignmentError", "check_week"]

WEEKS = ("03", "04", "05", "06", "07", "08")


class AssignmentError(Exception):
    """A bad week, source tree or output directory (the CLI exits with status 2)."""


def check_week(week: str | int) -> str:
    """The week as two digits ("5", "05" -> "05") when ASCII digits name one of WEEKS."""
    text, digits = str(week), str(week).lstrip("0")
    if text.isdigit() and len(digits) <= 2:  # WEEKS are ASCII: other digits stay unknown
        text = digits.zfill(2)
    if text not in WEEKS:
        raise AssignmentError(f"week {week!r}: expected one of {', '.join(WEEKS)}")
    return text
