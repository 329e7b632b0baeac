"""The student README's shared section and rtpy's README fitted to a student repository
(rtpy.grading.student_readme)."""

from __future__ import annotations

from pathlib import Path

from rtpy.grading.student_readme import DROPPED_SECTIONS, student_rtpy_readme, workflow_section

ROOT = Path(__file__).resolve().parents[2]


def test_the_workflow_section_says_how_to_install_grade_and_render():
    text = workflow_section("05", ["rtpy/light.py", "rtpy/scene.py"], ["tests/test_light.py"])
    assert "pip install -e '.[test]'" in text  # pytest comes with the test extra
    assert "python -m rtpy grade 05" in text
    assert 'python -m pytest -m ""' in text
    assert "--width 160 --spp 8 --workers 2" in text  # the quick loop, with measured times
    assert "to 25 minutes" in text and "7 seconds" in text
    assert "- `rtpy/light.py`\n- `rtpy/scene.py`\n" in text  # the files that are graded
    assert "ignores every other" in text and "- `tests/test_light.py`" in text


def test_rtpy_readme_for_students_has_no_numpy_commands():
    original = (ROOT / "README.md").read_text()
    assert "--backend numpy" in original  # what there is to take out
    text = student_rtpy_readme(original)
    assert "--backend numpy" not in text and "scalar|numpy" not in text
    assert not any(f"\n## {title}\n" in text for title in DROPPED_SECTIONS)
    assert "withheld" in text and "## Rendering" in text
