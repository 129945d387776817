"""The Blender side of the engine: every module here may import bpy. `reader` turns a Blender
scene into a `SceneData`; `cli` is the command line (`python -m addon.cli`, `blender -c dimred`)."""
