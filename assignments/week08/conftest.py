"""The graders' `probe` fixture (rtpy.grading.judge.probe)."""

from rtpy.grading.judge import probe  # noqa: F401
