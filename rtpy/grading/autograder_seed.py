"""The seed of a grading run: fixed on a student's machine, fresh for every submission
under the autograder.

A grader that draws random inputs takes its seed from `grading_seed(default)`. Run
locally (`python -m rtpy grade`, pytest) it returns `default`, so a failure can be
reproduced. run_autograder sets SEED_VARIABLE to a new random number for every
submission, and each default then gives a different seed of its own: inputs that
change from run to run cannot be special-cased. A check that uses it must hold for
every seed, with its false-failure rate stated (docs/instructors.md, "Hidden checks").
"""

from __future__ import annotations

import os

import numpy as np

SEED_VARIABLE = "RTPY_GRADING_SEED"


def grading_seed(default: int) -> int:
    """`default`, or under the autograder a seed in [0, 2**63 - 1] drawn from the run's
    seed and `default` (two graders with different defaults get independent seeds)."""
    text = os.environ.get(SEED_VARIABLE)
    if text is None or text == "":
        return default
    try:
        run = int(text)
    except ValueError:
        raise ValueError(f"{SEED_VARIABLE}={text!r}: expected a whole number") from None
    if run < 0 or default < 0:
        raise ValueError(f"seeds must be >= 0, got {SEED_VARIABLE}={run} and default={default}")
    state = int(np.random.SeedSequence([run, default]).generate_state(1, np.uint64)[0])
    return state >> 1  # 63 bits: a render's seed is at most 2**63 - 1


def grading_rng(default: int) -> np.random.Generator:
    """A numpy generator seeded with grading_seed(default)."""
    return np.random.default_rng(grading_seed(default))
