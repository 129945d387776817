"""Ground-truth harness (development only, not shipped in the extension).

Physics is the test oracle: `spec` describes closed Lambertian rooms, `build` makes them in
Blender, `render` renders each with and without the object to remove (Cycles, same seed, in a
subprocess, cached), `metrics` scores an engine's edit against the rendered truth.
"""
