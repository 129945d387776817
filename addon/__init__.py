"""The engine of Diminished Reality: numpy only, importable and testable without Blender.

Everything here takes and returns arrays; `blender/` is the one sub-package that imports bpy
(the reader that turns a Blender scene into a `SceneData`, and the command line).
"""
