"""The per-scene settings `scene.dimred` that the operators read and the panel shows."""
from __future__ import annotations

import bpy
from bpy.props import (
    BoolProperty,
    CollectionProperty,
    EnumProperty,
    FloatProperty,
    FloatVectorProperty,
    IntProperty,
    PointerProperty,
    StringProperty,
)

QUALITY_ITEMS = (
    ("draft", "Draft", "Fewest patches, light senders and bounces: fastest, coarsest shadows and relighting"),
    ("balanced", "Balanced", "The default trade-off between run time and accuracy, as on the command line"),
    ("final", "Final", "Most patches, light senders and bounces: slowest, most accurate"),
)


# Settings that override the preset's engine parameter of the same name (addon.quality.Params).
OVERRIDABLE = ("patches", "max_senders", "max_bounces", "raster_cell", "synth_neighbourhood",
               "synth_generations", "seed")


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
    override_parameters: BoolProperty(
        name="Override Preset",
        description="Use the parameters below instead of the quality preset's",
    )
    patches: IntProperty(
        name="Patches", min=20, soft_max=5000, default=500,
        description="Radiosity patches on the room: more resolve the light's change on walls and floor "
                    "more finely, and cost time in proportion",
    )
    max_senders: IntProperty(
        name="Light Senders", min=1, soft_max=256, default=32,
        description="Most bright patches (lamps, sunlit areas) whose shadows are traced exactly: more catch "
                    "faint secondary shadows, each one costs a visibility pass",
    )
    max_bounces: IntProperty(
        name="Bounces", min=0, soft_max=32, default=8,
        description="How many times the change of light is passed around the room: more remove the "
                    "object's colour bleeding further away, each costs a transport step",
    )
    raster_cell: FloatProperty(
        name="Fill Cell", min=0.2, soft_max=3.0, default=0.7,
        description="Cell of the plane raster the fill is synthesised on, in panorama pixels: smaller keeps "
                    "finer texture, larger is faster",
    )
    synth_neighbourhood: IntProperty(
        name="Neighbourhood", min=3, soft_max=15, default=7,
        description="Synthesis window in cells (odd): larger continues larger structures such as tile lines, "
                    "slower",
    )
    synth_generations: IntProperty(
        name="Generations", min=1, soft_max=6, default=2,
        description="Synthesis passes per pyramid level: more settle the seams, slower",
    )
    seed: IntProperty(
        name="Seed", min=0, default=0,
        description="Random seed of the fill: the same seed gives the same result, another seed another fill",
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

    def overrides(self) -> dict[str, float | int]:
        """The engine parameters set here, when they override the preset (else none)."""
        if not self.override_parameters:
            return {}
        return {name: getattr(self, name) for name in OVERRIDABLE}

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
