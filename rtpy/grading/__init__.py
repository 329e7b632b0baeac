"""Weekly assignments: the student repositories made from rtpy's solution regions,
and the graders that score them."""

from .graders import *  # noqa: F403
