"""The pages generated from the task maps (rtpy.grading.task_pages): every week's README
and docs/task-map.md are what the maps give (a map edited without regenerating them
fails here), and they state what the maps say."""

from __future__ import annotations

import os
import re
import shlex
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from rtpy.grading.task_pages import TASK_MAP_PAGE, duration, stale_pages, write_pages
from rtpy.grading.tasks import load_week, load_weeks

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
        words = " ".join(text.split())
        assert f"takes about {week.render_time} with the scalar backend" in words
        assert "`--time 30`" in words and "`--sampler sobol`" in words


def test_durations_read_as_hours_and_minutes():
    assert [duration(m) for m in (25, 60, 95, 240)] == ["25 min", "1 h", "1 h 35 min", "4 h"]


def test_each_task_section_shows_the_render_of_the_work_so_far():
    for week in load_weeks(ROOT):
        text = (ROOT / "assignments" / f"week{week.week}" / "README.md").read_text()
        for t in week.graded:
            section = text.split(f"### {t.number} {t.title}")[1].split("\n### ")[0]
            if t.render:
                assert f"python -m rtpy render {t.render}\n" in section
            else:
                words = " ".join(section.split())
                assert f"`python -m rtpy grade {week.week}` checks it" in words


def student_repository_after(week: str, task: str, dest: Path) -> Path:
    """Week's student repository with its tasks up to `task` ("8.2") written (the
    reference's regions), the later ones still stubs."""
    from rtpy.grading.assignment import find_regions, make_assignment, rewrite, withheld
    from rtpy.grading.tasks import task_numbers

    make_assignment(week, dest, ROOT)
    numbers = task_numbers(ROOT)
    done = {t.number for t in load_week(ROOT / "assignments" / f"week{week}").tasks}
    done = {n for n in done if float(n.split(".")[1]) <= float(task.split(".")[1])}

    def stub(r):
        number = numbers.get((r.path.as_posix(), r.function))
        return r.stub(number) if withheld(r.week, week) and number not in done else None

    for rel in sorted({r.path for r in find_regions(ROOT)}):
        (dest / rel).write_text(rewrite(ROOT / rel, ROOT, stub))
    return dest


RENDERS = [(w.week, t) for w in load_weeks(ROOT) for t in w.graded if t.render]


@pytest.mark.slow
@pytest.mark.parametrize("week,task", RENDERS, ids=[t.id for _, t in RENDERS])
def test_a_task_render_renders_once_the_tasks_up_to_it_are_written(tmp_path, week, task):
    """The README's command, in a student repository where the tasks up to this one
    are written (smaller and quicker), writes an image; a task earlier it stops with
    the one line naming a task that is not written yet."""
    repo = student_repository_after(week, task.number, tmp_path / "repo")
    command = [sys.executable, "-m", "rtpy", "render", *shlex.split(task.render)]
    command += ["--width", "32", "--spp", "1", "-q", "-o", "out.png"]
    env = {**os.environ, "PYTHONPATH": str(repo)}
    run = subprocess.run(command, cwd=repo, env=env, capture_output=True, text=True)
    assert run.returncode == 0 and (repo / "out.png").is_file(), run.stderr
    index = [t.number for t in load_week(ROOT / "assignments" / f"week{week}").tasks]
    before = index[index.index(task.number) - 1] if index.index(task.number) else None
    if before is None:
        return
    earlier = student_repository_after(week, before, tmp_path / "earlier")
    run = subprocess.run(command, cwd=earlier, env={**env, "PYTHONPATH": str(earlier)},
                         capture_output=True, text=True)  # fmt: skip
    assert run.returncode == 2 and not (earlier / "out.png").exists()
    assert len(run.stderr.splitlines()) == 1
    assert re.match(r"rtpy: error: task \d+\.\d+ is not written yet: ", run.stderr)
