"""Weekly assignments: the student repositories made from rtpy's solution regions,
and the graders that score them."""

from .graders import (
    assert_image_matches,
    assert_render_matches,
    compare,
    grade,
    load_reference,
    points,
    render_stack,
    save_reference,
    score_table,
    summarize,
    write_json,
)

__all__ = [
    "assert_image_matches",
    "assert_render_matches",
    "compare",
    "grade",
    "load_reference",
    "points",
    "render_stack",
    "save_reference",
    "score_table",
    "summarize",
    "write_json",
]
