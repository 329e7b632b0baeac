"""The command line (`python -m rtpy`): rendering, scenes, grading, `bench`."""
