"""The pages generated from the task map: every week's README (assignments/weekNN/
README.md, which becomes the student repository's README) and docs/task-map.md, the
instructors' overview of all weeks with the graders of every task.

    python scripts/make_task_docs.py           # rewrite them
    python scripts/make_task_docs.py --check   # list those that are out of date

tests/grading/test_task_pages.py fails when a generated page differs from what the
maps give, so a map edited without regenerating its pages is caught.
"""

from __future__ import annotations

import textwrap
from collections.abc import Callable
from pathlib import Path

from .tasks import ROOT, Task, Week, load_weeks, method_file

TASK_MAP_PAGE = "docs/task-map.md"
GENERATED = "<!-- Generated from assignments/{source} by scripts/make_task_docs.py. -->\n"

RENDER_SETTINGS = """## Render settings

Submit PNG renders made with **at least 100 samples per pixel** (`--spp 100`; the course
asks 128 for week 7), **max depth at least 5** (`--max-depth 5`), **width 480** and a
**16:9** image (`--width 480`; the scenes here are 16:9). For example

```sh
python -m rtpy render SCENE --spp 128 --max-depth 5 --width 480 --workers 2 -o out.png
```

The scalar backend renders your code (the numpy backend is withheld from assignment
repositories). A material of your own, in a file of its own and registered with
`@rtpy.materials.register_material("name")`, renders without editing rtpy:
`python -m rtpy render my_scene.toml --plugin my_material.py` (the scene uses
`type = "name"`).
"""

DRAFTS = """
On a machine of 2 cores the submission render of one of this week's scenes takes
about {time} with the scalar backend (`--workers 2`, measured with the reference
solution; your code may take longer). To draft faster: `--time 30`
(whole passes until 30 s are spent: a noisier image, sooner), a smaller `--width 240`
(a quarter of the pixels) and `--sampler sobol` (less noise for the same samples).
"""


def render_time(week: Week) -> str:
    """What the README says of the submission render's time, if it was measured."""
    return DRAFTS.format(time=week.render_time) if week.render_time else ""


GRADING = """## Grading

`python -m rtpy grade {week}` runs the graders in `assignments/week{week}/` and prints a
score table grouped by task, with each task's subtotal (Gradescope shows one group per
task, numbered as in the table above); each failed test says what is wrong and in
which method. `--json results.json` writes the Gradescope results file. The graders
check your code against the formulas at random inputs, check sampling with statistical
tests (chi-square, z-tests against the measured noise) and compare small renders with
renders of the reference solution, so a mistake that only changes the brightness (a
missing 1/r², 1/pdf or 1/π, light counted twice) loses points even when the image
looks plausible.{extensions}
"""

SUBMIT = """## What to submit

Your repository (the methods marked `TODO(week{week})`), the renders listed above, and a
short text answering the questions.
"""


def duration(minutes: int) -> str:
    """95 -> "1 h 35 min"."""
    hours, rest = divmod(minutes, 60)
    if not hours:
        return f"{rest} min"
    return f"{hours} h {rest} min" if rest else f"{hours} h"


def by_file(names: tuple[str, ...], root: Path) -> list[tuple[str, list[str]]]:
    """[(file, [qualified names in it])] of rtpy names, in their order."""
    files: dict[str, list[str]] = {}
    for name in names:
        path, qualname = method_file(name, root)
        files.setdefault(path, []).append(qualname)
    return list(files.items())


def methods_text(task: Task, root: Path) -> str:
    """ "`A.f`, `A.g` (`rtpy/a.py`); `h` (`rtpy/b.py`)"."""
    return "; ".join(
        f"{', '.join(f'`{m}`' for m in names)} (`{path}`)"
        for path, names in by_file(task.methods, root)
    )


def scene_text(week: Week, scene: str) -> str:
    """A render's scene as the student types it."""
    if scene.endswith(".toml"):
        return f"`assignments/week{week.week}/{scene}`"
    return f"the bundled `{scene}`"


def paragraph(text: str, first: str = "") -> str:
    """text as one paragraph wrapped at 88 columns, after `first` ("- " for a bullet,
    whose further lines are indented to match)."""
    return textwrap.fill(
        " ".join(text.split()),
        88,
        initial_indent=first,
        subsequent_indent=" " * len(first),
        break_long_words=False,
        break_on_hyphens=False,
    )


def task_section(task: Task, root: Path, shown_by: Task | None = None) -> str:
    """A task's section: its methods, its text and the render that shows the work done
    so far (`shown_by`: the first task from this one on that names a render)."""
    if task.render:
        see = f"See your work so far:\n\n```sh\npython -m rtpy render {task.render}\n```\n"
    elif shown_by is not None:
        see = (
            paragraph(
                f"Nothing renders this yet: the first render of it comes with task "
                f"{shown_by.number} ({shown_by.title}). `python -m rtpy grade {task.id[:2]}` "
                "checks it now."
            )
            + "\n"
        )
    else:
        see = paragraph(f"`python -m rtpy grade {task.id[:2]}` checks it.") + "\n"
    return (
        f"### {task.number} {task.title} — {task.points:g} points, about "
        f"{duration(task.minutes)}\n\n{paragraph(methods_text(task, root))}\n\n"
        f"{paragraph(task.text)}\n\n{see}"
    )


def shown_by(tasks: tuple[Task, ...], k: int) -> Task | None:
    """The first of tasks[k:] that names a render."""
    return next((t for t in tasks[k:] if t.render), None)


def week_readme(week: Week, root: Path = ROOT) -> str:
    """The student README of a week, from its task map."""
    w = week.week
    graded, extensions = week.graded, week.extensions
    minutes = sum(t.minutes for t in graded)
    out = [
        GENERATED.format(source=f"week{w}/tasks.toml"),
        f"# Week {w} — {week.title}\n\n"
        + paragraph(
            f"This week follows lecture {week.lecture} of the course, *{week.lecture_title}*. "
            f"Its tasks take about {duration(minutes)} (an estimate); the renders and "
            "questions come on top."
        )
        + "\n",
        "## After this week you can\n\n" + "".join(paragraph(g, "- ") + "\n" for g in week.goals),
        "## Tasks\n\n"
        "Do them in this order, the lecture's. Each method to write raises\n"
        f'`NotImplementedError("week{w} task: ...")` until you write it; its docstring is the\n'
        f'specification, and `grep -rn "TODO(week{w})" rtpy` lists them. Everything else the\n'
        "week needs is given, readable code.\n\n"
        "| task | methods | points | time |\n|---|---|---|---|\n"
        + "".join(
            f"| {t.number} {t.title} | {methods_text(t, root)} | {t.points:g} | "
            f"{duration(t.minutes)} |\n"
            for t in week.tasks
        )
        + f"| | total | {sum(t.points for t in graded):g} | {duration(minutes)} |\n",
        *(task_section(t, root, shown_by(graded, k)) for k, t in enumerate(graded)),
    ]
    if extensions:
        out.append(
            "## Extension tasks (optional, 0 points)\n\n"
            "Not part of the week's score: their graders run in a group of their own and\n"
            "report passed or failed.\n"
        )
        out.extend(task_section(t, root, shown_by(extensions, k)) for k, t in enumerate(extensions))
    if week.readings:
        out.append("## Given code to read\n")
        for r in week.readings:
            out.append(
                f"### {r.title}\n\n{paragraph(given_text(r.code, root))}\n\n"
                f"{paragraph(r.text)}\n\n{paragraph(f'**Question.** {r.question}')}\n"
            )
    out.append(
        "## Renders and questions\n\n"
        + "".join(
            paragraph(f"{scene_text(week, r.scene)}: {r.text}", "- ") + "\n" for r in week.renders
        )
    )
    out.append(RENDER_SETTINGS + render_time(week))
    note = (
        " Extension tasks are graded apart: their tests show passed or failed and are "
        "worth 0 points."
        if extensions
        else ""
    )
    out.append(GRADING.format(week=w, extensions=note))
    out.append(SUBMIT.format(week=w))
    return "\n".join(out)


def given_text(names: tuple[str, ...], root: Path) -> str:
    """ "`rtpy/a.py`: `f`, `g`; `rtpy/b.py`: `h`"."""
    return "; ".join(
        f"`{path}`: " + ", ".join(f"`{n}`" for n in qualnames)
        for path, qualnames in by_file(names, root)
    )


def task_map_page(weeks: list[Week], graders: Callable[[str], list], root: Path = ROOT) -> str:
    """docs/task-map.md: every week's lecture, goals and tasks with their graders.
    graders(week) gives the week's collected graders (rtpy.grading.graders)."""
    out = [
        GENERATED.format(source="weekNN/tasks.toml"),
        "# The task map\n\n"
        "What each week asks of a student, from the week's task map\n"
        "`assignments/weekNN/tasks.toml` (edit the maps, then run\n"
        "`python scripts/make_task_docs.py`, which writes this page and every week's\n"
        "README). Each week follows one lecture; each task is one course-shaped method or a\n"
        "small group of them, the solution regions a student writes, in the order the\n"
        'lecture builds them. The graders name their task (`@points(3, task="05.1")`),\n'
        "`python -m rtpy grade` groups them by it, and Gradescope numbers them task.test\n"
        "(5.1.1). Extension tasks are optional, worth 0 points and graded apart. How the\n"
        "map is checked against the code: [instructors.md](instructors.md#the-task-map).\n",
        "| week | lecture | tasks | points | time |\n|---|---|---|---|---|\n"
        + "".join(
            f"| {w.week} {w.title} | {w.lecture} {w.lecture_title} | {len(w.graded)}"
            + (f" + {len(w.extensions)} optional" if w.extensions else "")
            + f" | {sum(t.points for t in w.graded):g} | "
            f"{duration(sum(t.minutes for t in w.graded))} |\n"
            for w in weeks
        ),
    ]
    for w in weeks:
        by_task: dict[str, list[str]] = {}
        for g in graders(w.week):
            by_task.setdefault(g.task, []).append(f"`{g.nodeid.split('::')[-1]}` ({g.max_score:g})")
        out.append(
            f"## Week {w.week} — {w.title}\n\n"
            f"Lecture {w.lecture}, *{w.lecture_title}*; the student README is\n"
            f"[assignments/week{w.week}/README.md](../assignments/week{w.week}/README.md).\n\n"
            + "".join(paragraph(g, "- ") + "\n" for g in w.goals)
            + "\n| task | methods | points | time | graders |\n|---|---|---|---|---|\n"
            + "".join(
                f"| {t.number} {t.title} | "
                f"{methods_text(t, root)} | {t.points:g} | {duration(t.minutes)} | "
                f"{', '.join(by_task.get(t.id, ['none']))} |\n"
                for t in w.tasks
            )
        )
        lines = [
            f"- Given code to read: {r.title} ({given_text(r.code, root)})" for r in w.readings
        ]
        lines += [f"- Render: {scene_text(w, r.scene)}" for r in w.renders]
        out.append("\n".join(lines) + "\n")
    return "\n".join(out)


def generated_pages(root: Path = ROOT) -> dict[Path, str]:
    """Every generated page (path under root -> its text) from the maps under root."""
    from .graders import collect_graders

    weeks = load_weeks(root)
    pages = {root / f"assignments/week{w.week}/README.md": week_readme(w, root) for w in weeks}
    pages[root / TASK_MAP_PAGE] = task_map_page(
        weeks, lambda week: collect_graders(week, root), root
    )
    return pages


def stale_pages(root: Path = ROOT) -> list[str]:
    """The generated pages that differ from what the maps give (paths under root)."""
    return [
        path.relative_to(root).as_posix()
        for path, text in generated_pages(root).items()
        if not path.is_file() or path.read_text(encoding="utf-8") != text
    ]


def write_pages(root: Path = ROOT) -> list[Path]:
    """Write every generated page; the paths written."""
    pages = generated_pages(root)
    for path, text in pages.items():
        path.write_text(text, encoding="utf-8")
    return list(pages)
