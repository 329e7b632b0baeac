"""Render the reference data of the assignments' render graders with rtpy's solution.

Every grader module `assignments/weekNN/test_weekNN.py` with a render defines REFERENCE
and either make_reference_summary(probe), written to `reference/<REFERENCE["name"]>.npz`
(mean image, per-sample variance, sample count), or make_reference_image(probe),
written to `.npy`, and each of MORE_REFERENCES {name: function(probe) -> arrays},
written to `reference/<name>.npz`; the probe is answered in this process, by rtpy's solution.
Run after changing a graded scene or the physics:
    python scripts/make_assignment_references.py [WEEK ...]
"""

import importlib.util
import sys
from pathlib import Path

import numpy as np

from rtpy.grading import save_reference
from rtpy.grading.graders import local_probe

ROOT = Path(__file__).resolve().parent.parent


def main(weeks: list[str]) -> None:
    for folder in sorted((ROOT / "assignments").glob("week*")):
        if weeks and folder.name[4:] not in weeks:
            continue
        path = folder / f"test_{folder.name}.py"
        spec = importlib.util.spec_from_file_location(f"grader_{folder.name}", path)
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        if not hasattr(module, "REFERENCE"):
            continue
        probe = local_probe(folder.name[4:], ROOT, in_process=True)
        name = folder / "reference" / module.REFERENCE["name"]
        name.parent.mkdir(exist_ok=True)
        if hasattr(module, "make_reference_summary"):  # noisy: mean and variance
            out = name.with_suffix(".npz")
            save_reference(out, module.make_reference_summary(probe))
        else:  # deterministic: the image
            out = name.with_suffix(".npy")
            np.save(out, module.make_reference_image(probe))
        print(f"wrote {out.relative_to(ROOT)}")
        for more, make in getattr(module, "MORE_REFERENCES", {}).items():
            out = folder / "reference" / f"{more}.npz"
            save_reference(out, make(probe))
            print(f"wrote {out.relative_to(ROOT)}")


if __name__ == "__main__":
    main(sys.argv[1:])
