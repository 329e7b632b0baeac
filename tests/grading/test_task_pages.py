"""The pages generated from the task maps (rtpy.grading.task_pages): every week's README
and docs/task-map.md are what the maps give (a map edited without regenerating them
fails here), and they state what the maps say."""

from __future__ import annotations

import re
import shutil
from pathlib import Path

from rtpy.grading.task_pages import TASK_MAP_PAGE, duration, stale_pages, write_pages
from rtpy.grading.tasks import load_weeks

ROOT = Path(__file__).resolve().parents[2]


def test_the_generated_pages_are_up_to_date():
    stale = stale_pages(ROOT)
    assert stale == [], f"out of date: {stale}; run python scripts/make_task_docs.py"


def test_a_map_edited_without_regenerating_is_caught(tmp_path):
    (tmp_path / "rtpy").symlink_to(ROOT / "rtpy")
    (tmp_path / "docs").mkdir()
    shutil.copytree(
        ROOT / "assignments" / "week05",
        tmp_path / "assignments" / "week05",
        ignore=shutil.ignore_patterns("__pycache__"),
    )
    write_pages(tmp_path)
    assert stale_pages(tmp_path) == []
    tasks = tmp_path / "assignments" / "week05" / "tasks.toml"
    tasks.write_text(tasks.read_text().replace('title = "Shadow rays"', 'title = "Shadows"'))
    assert stale_pages(tmp_path) == ["assignments/week05/README.md", TASK_MAP_PAGE]


def test_each_readme_states_the_lecture_the_tasks_their_points_and_times():
    for week in load_weeks(ROOT):
        text = (ROOT / "assignments" / f"week{week.week}" / "README.md").read_text()
        assert f"follows lecture {week.lecture} of the course" in text
        rows = dict(
            re.findall(r"^\| (\d+\.\d+ [^|]+?) \| [^|]+ \| ([\d.]+) \| [^|]+ \|$", text, re.M)
        )
        assert rows == {f"{t.number} {t.title}": f"{t.points:g}" for t in week.tasks}
        total = sum(t.points for t in week.graded)
        assert f"| | total | {total:g} | {duration(sum(t.minutes for t in week.graded))} |" in text
        for t in week.tasks:
            assert f"### {t.number} {t.title} — {t.points:g} points" in text
        assert ("## Extension tasks (optional, 0 points)" in text) == bool(week.extensions)
        assert ("## Given code to read" in text) == bool(week.readings)


def test_durations_read_as_hours_and_minutes():
    assert [duration(m) for m in (25, 60, 95, 240)] == ["25 min", "1 h", "1 h 35 min", "4 h"]
