"""Weekly assignments: the student repositories made from rtpy's solution regions,
and the graders that score them: probes that run the student's code in a process of
its own (rtpy.grading.probes, rtpy.grading.child) and verdicts made by the judge
(rtpy.grading.judge), the only process that decides a score."""

from .graders import (
    assert_image_matches,
    assert_render_matches,
    assert_renders_match,
    compare,
    grade,
    load_reference,
    points,
    reference_summary,
    save_reference,
    scene_uses,
    summarize,
)

__all__ = [
    "assert_image_matches",
    "assert_render_matches",
    "assert_renders_match",
    "compare",
    "grade",
    "load_reference",
    "points",
    "reference_summary",
    "save_reference",
    "scene_uses",
    "summarize",
]
