"""Render the reference data of the assignments' render graders with rtpy's solution.

Every grader module `assignments/weekNN/test_weekNN.py` that defines REFERENCE and
make_reference_summary() gets `assignments/weekNN/reference/<REFERENCE["name"]>.npz`
(mean image, per-sample variance, sample count). Run after changing a graded
scene or the physics:  python scripts/make_assignment_references.py [WEEK ...]
"""

import importlib.util
import sys
from pathlib import Path

from rtpy.grading import save_reference

ROOT = Path(__file__).resolve().parent.parent


def main(weeks: list[str]) -> None:
    for folder in sorted((ROOT / "assignments").glob("week*")):
        if weeks and folder.name[4:] not in weeks:
            continue
        path = folder / f"test_{folder.name}.py"
        spec = importlib.util.spec_from_file_location(f"grader_{folder.name}", path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        if not hasattr(module, "make_reference_summary"):
            continue
        out = folder / "reference" / f"{module.REFERENCE['name']}.npz"
        out.parent.mkdir(exist_ok=True)
        save_reference(out, module.make_reference_summary())
        print(f"wrote {out.relative_to(ROOT)}")


if __name__ == "__main__":
    main(sys.argv[1:])
