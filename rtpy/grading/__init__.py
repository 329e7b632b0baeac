"""Weekly assignments: the student repositories made from rtpy's solution regions,
and the graders that score them."""

from .graders import (
    assert_image_matches,
    assert_render_matches,
    assert_renders_match,
    compare,
    deterministic_image,
    grade,
    load_reference,
    points,
    reference_summary,
    render_stack,
    save_reference,
    score_table,
    summarize,
    write_json,
)

__all__ = [
    "assert_image_matches",
    "assert_render_matches",
    "assert_renders_match",
    "compare",
    "deterministic_image",
    "grade",
    "load_reference",
    "points",
    "reference_summary",
    "render_stack",
    "save_reference",
    "score_table",
    "summarize",
    "write_json",
]
