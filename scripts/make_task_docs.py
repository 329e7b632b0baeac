"""Write every week's README (assignments/weekNN/README.md) and docs/task-map.md from
the task maps assignments/weekNN/tasks.toml (rtpy.grading.task_pages).

    python scripts/make_task_docs.py           # rewrite them
    python scripts/make_task_docs.py --check   # exit 1 listing those out of date
"""

import sys

from rtpy.grading.task_pages import ROOT, stale_pages, write_pages


def main(args: list[str]) -> int:
    if args == ["--check"]:
        stale = stale_pages()
        for path in stale:
            print(f"out of date: {path}")
        return 1 if stale else 0
    if args:
        print(__doc__, file=sys.stderr)
        return 2
    for path in write_pages():
        print(f"wrote {path.relative_to(ROOT)}")
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
