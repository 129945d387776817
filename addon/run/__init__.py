"""Running a job away from Blender's main thread: the request and outcome of one run (`job`)
and the worker thread that runs it (`worker`)."""
