"""The engine of Diminished Reality: numpy only, importable and testable without Blender.

`bridge` is the one module here that imports bpy; everything else takes and returns arrays.
"""
