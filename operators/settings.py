"""The per-scene settings `scene.dimred` that the operators read and the panel shows."""
from __future__ import annotations

import bpy
from bpy.props import (
    BoolProperty,
    CollectionProperty,
    EnumProperty,
    FloatVectorProperty,
    PointerProperty,
    StringProperty,
)

QUALITY_ITEMS = (
    ("draft", "Draft", "Fewest patches, light senders and bounces: fastest, coarsest shadows and relighting"),
    ("balanced", "Balanced", "The default trade-off between run time and accuracy, as on the command line"),
    ("final", "Final", "Most patches, light senders and bounces: slowest, most accurate"),
)


def _is_mesh(_settings: bpy.types.PropertyGroup, obj: bpy.types.Object) -> bool:
    return obj.type == 'MESH'


class DimredSurface(bpy.types.PropertyGroup):
    """One surface the removal is asked to edit (the floor under the object, a wall)."""

    object: PointerProperty(name="Surface", type=bpy.types.Object, poll=_is_mesh)


class DimredRemoval(bpy.types.PropertyGroup):
    """One object removed from the panorama, in order, with its own difference image.

    The world layer shows the sum of all of them; a later removal works on HDRI + the earlier ones.
    """

    object_name: StringProperty(name="Object", description="The removed object")
    image: PointerProperty(name="Difference", description="This removal's own difference image", type=bpy.types.Image)


class DimredSettings(bpy.types.PropertyGroup):
    """What to remove, from where the panorama was taken, and how carefully."""

    probe_center: FloatVectorProperty(
        name="Probe Centre",
        description="Where the panorama was photographed from, in world space",
        subtype='XYZ',
        unit='LENGTH',
        size=3,
    )
    use_probe_center: BoolProperty(
        name="Use Probe Centre",
        description=(
            "Use the probe centre set here; otherwise an Empty named ProbeCenter, "
            "else the world origin"
        ),
    )
    target: PointerProperty(
        name="Object",
        description="The real object to remove from the panorama",
        type=bpy.types.Object,
        poll=_is_mesh,
    )
    surfaces: CollectionProperty(
        name="Surfaces",
        description="Surfaces to edit; when empty, the surfaces the removal reveals or relights are found automatically",
        type=DimredSurface,
    )
    quality: EnumProperty(name="Quality", items=QUALITY_ITEMS, default="balanced")
    output_dir: StringProperty(
        name="Output Folder",
        description="Folder for the difference image (// is the folder of the .blend file)",
        subtype='DIR_PATH',
        default="//dimred/",
    )
    storage: EnumProperty(
        name="Store Result",
        items=(
            ("FILE", "Beside the File", "Write the difference images into the output folder; the .blend refers to them"),
            ("PACK", "Packed", "Pack the difference images into the .blend: one self-contained file, larger to save"),
        ),
        default="FILE",
        description="Where the difference images live so that saving and reopening the .blend keeps the result",
    )
    removals: CollectionProperty(
        name="Removals",
        description="The objects removed so far, in order; the world shows all of them",
        type=DimredRemoval,
    )
    last_report: StringProperty(
        name="Last Report",
        description="The last removal's report, as JSON",
        options={'HIDDEN'},
    )

    def surface_names(self) -> tuple[str, ...]:
        """Names of the marked surfaces that still exist."""
        return tuple(item.object.name for item in self.surfaces if item.object is not None)


classes = (DimredSurface, DimredRemoval, DimredSettings)


def register() -> None:
    for cls in classes:
        bpy.utils.register_class(cls)
    bpy.types.Scene.dimred = PointerProperty(type=DimredSettings)


def unregister() -> None:
    del bpy.types.Scene.dimred
    for cls in reversed(classes):
        bpy.utils.unregister_class(cls)
