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
from mathutils import Matrix

# Standard library and the error type only: reading it keeps registering the add-on cheap.
from ..addon.quality import DEFAULT_QUALITY, DESCRIPTIONS, MIN_WORKING_WIDTH, Params

QUALITY_ITEMS = tuple((name, name.title(), description) for name, description in DESCRIPTIONS.items())

# Where the override settings start: the engine's own defaults, those of the default preset.
_DEFAULTS = Params()

# Settings that override the preset's engine parameter of the same name (addon.quality.Params).
OVERRIDABLE = ("patches", "max_senders", "max_bounces", "working_width", "raster_cell", "synth_neighbourhood",
               "synth_generations", "synth_structure", "seed", "insertion_passes")


def _is_mesh(_settings: bpy.types.PropertyGroup, obj: bpy.types.Object) -> bool:
    return obj.type == 'MESH'


def _is_still(_settings: bpy.types.PropertyGroup, image: bpy.types.Image) -> bool:
    # What the mask reader can read: one picture, not a render result, movie or tile set.
    return image.source in {'FILE', 'GENERATED'} and image.type == 'IMAGE'


def _target_changed(settings: bpy.types.PropertyGroup, _context: bpy.types.Context) -> None:
    # A Remove is likely next: its first preview wants a small copy of the panorama ready.
    if settings.target is not None:
        from .support import warmup

        warmup.warm(settings.id_data)


class DimredSurface(bpy.types.PropertyGroup):
    """One surface the removal is asked to edit (the floor under the object, a wall)."""

    object: PointerProperty(name="Surface", type=bpy.types.Object, poll=_is_mesh)


def _yaw_property(description: str) -> FloatProperty:
    # Degrees as a plain number, as the command line's --yaw takes it (an ANGLE property would
    # hold radians for scripts).
    return FloatProperty(name="Yaw", description=description, soft_min=-180.0, soft_max=180.0, precision=1)


def _distance_property(description: str) -> FloatProperty:
    # No hard minimum: a factor <= 0 must reach the operator and be refused with a message,
    # not be clamped silently into some other move.
    return FloatProperty(name="Distance", description=description, default=1.0, soft_min=0.1, soft_max=4.0,
                         step=1, precision=2)


YAW_DESCRIPTION = ("Degrees the object turns about the vertical axis through the probe centre, counter-clockwise "
                   "seen from above; its own orientation turns with it, so the photographed side keeps facing "
                   "the probe")
DISTANCE_DESCRIPTION = ("Factor on the object's horizontal distance from the probe centre (1 keeps it, 0.5 halves "
                        "it); the object stays on its support plane")


def _matrix(values) -> Matrix:
    return Matrix([values[row * 4:row * 4 + 4] for row in range(4)])


def _flat(matrix: Matrix) -> list[float]:
    return [value for row in matrix for value in row]


def _matrix_property(name: str, description: str) -> FloatVectorProperty:
    return FloatVectorProperty(name=name, description=description, size=16, options={'HIDDEN'})


class DimredRemoval(bpy.types.PropertyGroup):
    """One object removed from the panorama or relocated in it, in order, with its own
    difference image.

    The world layer shows the sum of all of them; a later removal works on HDRI + the earlier
    ones. A relocated object stays in the geometry at its new place; `photographed` keeps where
    the panorama shows it, which a new relocation starts from and Clear puts it back to.
    """

    object_name: StringProperty(name="Object", description="The removed or relocated object")
    image: PointerProperty(name="Difference", description="This removal's own difference image", type=bpy.types.Image)
    kind: EnumProperty(
        name="Kind",
        items=(("REMOVE", "Removed", "The object was removed from the panorama"),
               ("RELOCATE", "Relocated", "The object was moved to another place in the panorama")),
        default="REMOVE",
    )
    yaw: _yaw_property(YAW_DESCRIPTION)
    distance_scale: _distance_property(DISTANCE_DESCRIPTION)
    photographed: _matrix_property("Photographed Matrix",
                                   "The object's world matrix where the panorama shows it, row by row")

    def photographed_matrix(self) -> Matrix:
        return _matrix(self.photographed)

    def set_photographed_matrix(self, matrix: Matrix) -> None:
        self.photographed = _flat(matrix)


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
        update=_target_changed,
    )
    # Where the marked object stood when it was marked (the proxy aligned with the photograph):
    # Relocate "from transform" measures the artist's G/R move from there.
    marked_name: StringProperty(options={'HIDDEN'})
    marked_matrix: _matrix_property("Marked Matrix", "The marked object's world matrix when it was marked, row by row")
    surfaces: CollectionProperty(
        name="Surfaces",
        description=("Surfaces to edit; when empty, the surfaces the removal reveals or relights are found "
                     "automatically"),
        type=DimredSurface,
    )
    mask_image: PointerProperty(
        name="Mask",
        description=("Painted over the panorama, its size or an integer fraction of it: white adds to the region "
                     "the removal fills, black takes away, grey or transparent leaves it as the photograph shows it"),
        type=bpy.types.Image,
        poll=_is_still,
    )
    align_first: BoolProperty(
        name="Align to Photo First",
        description=("Align to Photo before removing or relocating: the proxy's pose is fitted to the object's "
                     "outline in the panorama, and the object keeps the fitted pose when the run succeeds"),
    )
    fit_height: BoolProperty(
        name="Fit Support Height",
        description=("Align to Photo fits the height of the surface the object stands on instead of its scale: "
                     "for a proxy whose size is known (from one viewpoint a smaller object and a nearer one look "
                     "alike)"),
    )
    photo_fit: StringProperty(
        name="Photo Fit",
        description="How the proxy fitted the photograph at the last run or Align to Photo, as JSON",
        options={'HIDDEN'},
    )
    quality: EnumProperty(name="Quality", items=QUALITY_ITEMS, default=DEFAULT_QUALITY)
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
        name="Patches", min=20, soft_max=5000, default=_DEFAULTS.patches,
        description="Radiosity patches on the room: more resolve the light's change on walls and floor "
                    "more finely, and cost time in proportion",
    )
    max_senders: IntProperty(
        name="Light Senders", min=1, soft_max=256, default=_DEFAULTS.max_senders,
        description="Most bright patches (lamps, sunlit areas) whose shadows are traced exactly: more catch "
                    "faint secondary shadows, each one costs a visibility pass",
    )
    max_bounces: IntProperty(
        name="Bounces", min=0, soft_max=32, default=_DEFAULTS.max_bounces,
        description="How many times the change of light is passed around the room: more remove the "
                    "object's colour bleeding further away, each costs a transport step",
    )
    working_width: IntProperty(
        name="Solve Width", min=MIN_WORKING_WIDTH, soft_max=4096, step=2, default=_DEFAULTS.working_width,
        description="The light is solved on a copy of the panorama at most this many pixels wide (even); the "
                    "full-size panorama takes it from there and is filled at its own size. Wider resolves finer "
                    "shadows and needs more time and memory",
    )
    raster_cell: FloatProperty(
        name="Fill Cell", min=0.2, soft_max=3.0, default=_DEFAULTS.raster_cell,
        description="Cell of the plane raster the fill is synthesised on, in panorama pixels: smaller keeps "
                    "finer texture, larger is faster",
    )
    synth_neighbourhood: IntProperty(
        name="Neighbourhood", min=3, soft_max=15, default=_DEFAULTS.synth_neighbourhood,
        description="Synthesis window in cells (odd): larger continues larger structures such as tile lines, "
                    "slower",
    )
    synth_generations: IntProperty(
        name="Generations", min=1, soft_max=6, default=_DEFAULTS.synth_generations,
        description="Synthesis passes per pyramid level: more settle the seams, slower",
    )
    synth_structure: BoolProperty(
        name="Structure", default=_DEFAULTS.synth_structure,
        description="Run tile and plank lines on through the fill, and continue a band that crosses the object "
                    "between two materials (a painted lane) as a straight strip; off: texture synthesis alone",
    )
    seed: IntProperty(
        name="Seed", min=0, default=_DEFAULTS.seed,
        description="Random seed of the fill: the same seed gives the same result, another seed another fill",
    )
    insertion_passes: IntProperty(
        name="Insertion Passes", min=1, max=8, default=_DEFAULTS.insertion_passes,
        description=("Relocate only: solver passes towards the moved object's new shadow and reflected light. "
                     "The first already holds the lamps' shadows; more settle the light it reflects, each costing "
                     "about a removal"),
    )
    yaw: _yaw_property(YAW_DESCRIPTION + ". Where Relocate starts; it keeps the last relocation's value")
    distance_scale: _distance_property(DISTANCE_DESCRIPTION + ". Where Relocate starts; it keeps the last "
                                       "relocation's value")
    storage: EnumProperty(
        name="Store Result",
        items=(
            ("FILE", "Beside the File",
             "Write the difference images into the output folder; the .blend refers to them"),
            ("PACK", "Packed", "Pack the difference images into the .blend: one self-contained file, larger to save"),
        ),
        default="FILE",
        description="Where the difference images live so that saving and reopening the .blend keeps the result",
    )
    removals: CollectionProperty(
        name="Removals",
        description="The objects removed or relocated so far, in order; the world shows all of them",
        type=DimredRemoval,
    )
    last_report: StringProperty(
        name="Last Report",
        description="The last removal's report, as JSON",
        options={'HIDDEN'},
    )

    def overrides(self) -> dict[str, float | int | bool]:
        """The engine parameters set here, when they override the preset (else none)."""
        if not self.override_parameters:
            return {}
        return {name: getattr(self, name) for name in OVERRIDABLE}

    def mark(self, obj: bpy.types.Object) -> None:
        """Make `obj` the target and remember where it stands now."""
        self.target = obj
        self.marked_name = obj.name
        self.marked_matrix = _flat(obj.matrix_world)

    def correct_marked(self, name: str, correction: Matrix) -> None:
        """Align to Photo moved object `name` by the world matrix `correction`: where it stood
        when marked moves with it, so a later hand-made move is measured from the fitted pose."""
        if self.marked_name == name:
            self.marked_matrix = _flat(correction @ _matrix(self.marked_matrix))

    def marked_placement(self) -> Matrix | None:
        """The target's world matrix when it was marked, if it was marked under its present name."""
        if self.target is None or self.marked_name != self.target.name:
            return None
        return _matrix(self.marked_matrix)

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
