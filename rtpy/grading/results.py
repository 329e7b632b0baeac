"""The results of grading a week: one builder for `python -m rtpy grade` and for the
Gradescope autograder, so that both number, name, score and show the tests alike.

Each test is numbered task.test ("5.1.1", by which Gradescope orders and groups them)
and named "<task title>: <first docstring line>", in the order of the week's task
map; the hidden checks come last, as the group "Hidden checks" (numbered after the
last task), visible after the due date. An extension task's tests are worth 0 points:
they show passed or failed and leave the score alone. A test's output is the judge's
message; when a task file could not be used (it is graded as its stub) the message
says so, and a failed render names the failed graders of the tasks its scene uses
(rtpy.grading.graders.scene_uses), all of them.
"""

from __future__ import annotations

import json
from pathlib import Path

from ..io.image import atomic_write
from .judge import Graded, Outcome

HIDDEN_TITLE = "Hidden checks"


def gradescope_results(
    tests: list[Graded],
    week_map=None,
    *,
    partial: bool = False,
    notes: list[str] | None = None,
    problems: dict[str, str] | None = None,
    task_functions: list[dict] | None = None,
    not_run: str = "not run",
) -> dict:
    """Gradescope's results dictionary. problems: task file -> why it was not used;
    task_functions: [{"path", "function"}] (to tie a stub's error to its file)."""
    tasks = {t.id: t for t in week_map.tasks} if week_map is not None else {}
    order = list(tasks)
    week_number = str(int(week_map.week)) if week_map is not None else "0"
    ranked = sorted(
        tests,
        key=lambda g: (g.hidden, order.index(g.task) if g.task in tasks else len(order)),
    )
    groups, counts = [], {}
    for g in ranked:
        task = tasks.get(g.task)
        group = (
            (task.number, task.title)
            if task is not None
            else (f"{week_number}.{len(order) + 1}", HIDDEN_TITLE if g.hidden else "Other")
        )
        counts[group] = counts.get(group, 0) + 1
        groups.append((group, f"{group[0]}.{counts[group]}"))
    entries = []
    for g, (group, number) in zip(ranked, groups, strict=True):
        outcome = g.outcome or Outcome(False, "not run yet" if partial else not_run)
        text = explain(outcome, problems or {}, task_functions or [])
        if outcome.renders and not outcome.passed:
            text += failed_in_scene(g, ranked, groups, tasks)
        entries.append(
            {
                "name": f"{group[1]}: {g.name}",
                "number": number,
                "score": g.max_score if outcome.passed else 0.0,
                "max_score": g.max_score,
                "status": "passed" if outcome.passed else "failed",
                "output": text,
                "visibility": "after_due_date" if g.hidden else "visible",
            }
        )
    header = list(notes or [])
    hidden = sum(e["max_score"] for e in entries if e["visibility"] != "visible")
    if hidden:
        header.append(
            f"Hidden checks ({hidden:g} of the {sum(e['max_score'] for e in entries):g} points) "
            "use new random inputs on every submission; you see them after the due date."
        )
    results = {
        "score": sum(e["score"] for e in entries),
        "max_score": sum(e["max_score"] for e in entries),
        "output": "\n".join(header),
        "visibility": "visible",
        "stdout_visibility": "hidden",
        "tests": entries,
    }
    return results


def scrub(results: dict, paths: dict[str, str]) -> dict:
    """results with each of `paths` (the judge's own folders, as any process may print
    them) replaced by what the student reads instead, in every text shown."""
    order = sorted(paths, key=len, reverse=True)  # a folder's children before itself

    def clean(text: str) -> str:
        for path in order:
            text = text.replace(path, paths[path])
        return text

    results["output"] = clean(results.get("output", ""))
    for test in results.get("tests", []):
        test["name"], test["output"] = clean(test["name"]), clean(test["output"])
    return results


def explain(outcome: Outcome, problems: dict, task_functions: list) -> str:
    """A failed test's output, with the file problem that explains a stub's error."""
    if outcome.passed:
        return ""
    text = outcome.output
    for task in task_functions:
        rel = task["path"]
        if rel in problems and f"task: {task['function']}" in text:
            text = f"{rel} was not used ({problems[rel]}), so this counts as not done. {text}"
            break
    return text


def failed_in_scene(render: Graded, ranked: list[Graded], groups: list, tasks: dict) -> str:
    """For a failed render: the visible graders that failed among those of the tasks
    its scene uses (rtpy.grading.graders.scene_uses) and of its own task, all of them,
    by task with the task's methods; "" when none failed."""
    from .graders import scene_tasks

    used = [*scene_tasks(render.nodeid), render.task]
    parts = []
    for task_id in dict.fromkeys(t for t in used if t in tasks):
        failed = [
            f"{number} {g.name}"
            for g, (_, number) in zip(ranked, groups, strict=True)
            if g.task == task_id
            and not g.hidden
            and g.outcome is not None
            and not g.outcome.passed
            and not g.outcome.renders
        ]
        if failed:
            task = tasks[task_id]
            methods = ", ".join(short_name(m) for m in task.methods)
            parts.append(f"{task.number} {task.title} ({methods}): {'; '.join(failed)}")
    if not parts:
        return ""
    return (
        "\nThis render's scene uses methods whose own checks failed; fix those first: "
        + ". ".join(parts)
        + "."
    )


def short_name(qualified: str) -> str:
    """ "Phong.BRDF" for "rtpy.materials.phong.Phong.BRDF", "cross" for "rtpy.vec3.cross"."""
    parts = qualified.split(".")
    return ".".join(parts[-2:]) if parts[-2][:1].isupper() else parts[-1]


def score_table(results: dict) -> str:
    """The results as a table: each task's line with its subtotal, then its tests with
    the output of those that failed (a 0-point extension test shows passed/failed)."""
    groups: dict[str, list[dict]] = {}
    for t in results["tests"]:
        groups.setdefault(t["number"].rpartition(".")[0], []).append(t)
    rows = []  # (indent, label, points, output)
    for number, tests in groups.items():
        title = tests[0]["name"].partition(": ")[0]
        got, most = sum(t["score"] for t in tests), sum(t["max_score"] for t in tests)
        rows.append((0, f"{number} {title}", f"{got:g}/{most:g}", ""))
        for t in tests:
            label = f"{t['number']} {t['name'].partition(': ')[2]}"
            pts = f"{t['score']:g}/{t['max_score']:g}" if t["max_score"] else t["status"]
            rows.append((4, label, pts, t["output"]))
    width = max([indent + len(label) for indent, label, _, _ in rows] + [4])
    lines = [f"{'task / test':<{width}}  points", "-" * (width + 8)]
    if results.get("output"):
        lines[:0] = [results["output"], ""]
    for indent, label, pts, output in rows:
        lines.append(f"{' ' * indent}{label:<{width - indent}}  {pts}")
        lines.extend(f"{' ' * (indent + 4)}{line}" for line in output.splitlines()[:6])
    lines.append("-" * (width + 8))
    lines.append(f"{'total':<{width}}  {results['score']:g}/{results['max_score']:g}")
    return "\n".join(lines)


def write_results(path: str | Path, results: dict) -> None:
    """Write results as JSON, atomically (a reader sees the old file or the new one)."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    text = json.dumps(results, indent=2) + "\n"
    atomic_write(path, lambda tmp: tmp.write_text(text, encoding="utf-8"))
