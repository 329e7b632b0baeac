"""The render engine: the render loop and its plans, pixel sums and resume
state; the backends and their registry; executors, worker processes and Dask;
signals, atomic files, the reading of user files, image writers, the display
transform, exit statuses, students' plugin files, memory, the version. Nothing
here is course material."""
