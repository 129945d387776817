"""One Remove or Relocate run inside Blender: gather on the main thread, compute, show, apply or
roll back.

`RemovalSession.begin` reads everything the engine needs from Blender (plain arrays, never a
bpy object, go to the engine); given a `Move`, the session relocates the object instead of
removing it and, on success, places the object where the move puts it. `run_here` computes on
the calling thread (background mode, scripts); `start` hands the work to a `Worker` thread and
`tick`, called from a modal operator's timer, shows progress and previews and applies the
result when it arrives. Every step that touches bpy runs on the main thread and is short:
files are decoded and written by the worker (the earlier results too: the session names their
files, writing packed ones out first), previews are small whatever the panorama's size, and
the main thread only renames the results into place and points images at them, which Blender
loads from the files itself. The diagnostics picture is drawn by the worker too (and staged
beside the difference when that goes to a file); the main thread copies its pixels into the
image "Dimred Diagnostics". On success a run with Align to Photo first leaves the object at
the fitted pose.

Running sessions are kept in `_running` so that file load, unregister and Blender's exit can
stop and join their threads (the one piece of module state; Blender cannot do it for us).
"""
from __future__ import annotations

import atexit
import json
import os
import shutil
import tempfile
import time
from collections.abc import Callable
from dataclasses import dataclass, field, replace
from typing import TYPE_CHECKING

import bpy
import numpy as np
from mathutils import Matrix

from ...addon.errors import Cancelled, DimredError
from ...addon.run.worker import Worker
from . import pictures, warmup, world_layer

if TYPE_CHECKING:  # the engine is imported only when a run starts
    from ...addon.callbacks import RunCallbacks
    from ...addon.relocation.fixedview import Move
    from ...addon.run.job import Layer, RemovalOutcome, RemovalRequest
    from ...addon.run.preview import Preview
    from ...addon.scene import SceneData

PREVIEW_IMAGE = "DimRed Preview"
PREVIEW_MASK_IMAGE = "DimRed Preview Mask"
# Seconds a cancelled worker may take to notice; the engine checks far more often than this.
STOP_TIMEOUT = 5.0
# Seconds between a waiting run's checks for a cancel.
WAIT_INTERVAL = 0.05

_running: list[RemovalSession] = []


def output_folder(settings: bpy.types.PropertyGroup) -> str:
    """The absolute output folder; a '//' path needs a saved .blend to be relative to."""
    raw = settings.output_dir.strip() or "//"
    if raw.startswith("//") and not bpy.data.filepath:
        raise DimredError(
            f"The output folder '{raw}' is relative to the .blend file, which is not saved yet: "
            "save it first, choose an absolute folder, or pack the result into the file"
        )
    return os.path.normpath(bpy.path.abspath(raw))


def layer_filename(world: bpy.types.World) -> str:
    """One layer file per world, so scenes sharing an output folder do not collide."""
    return f"{bpy.path.clean_name(world.name)}_difference.exr"


def own_filename(world: bpy.types.World, object_name: str, kind: str = "difference.exr") -> str:
    return f"{bpy.path.clean_name(world.name)}_{bpy.path.clean_name(object_name)}_{kind}"


def probe_center(settings: bpy.types.PropertyGroup) -> tuple[float, float, float] | None:
    # None lets the reader apply the contract's fallbacks (an Empty named ProbeCenter, the origin).
    return tuple(settings.probe_center) if settings.use_probe_center else None


def relocated_matrix(settings: bpy.types.PropertyGroup, name: str) -> Matrix | None:
    """The photographed matrix stored by the relocation of object `name`, if it was relocated."""
    index = _index(settings, name)
    entry = settings.removals[index] if index >= 0 else None
    return entry.photographed_matrix() if entry is not None and entry.kind == 'RELOCATE' else None


def photographed_matrix(settings: bpy.types.PropertyGroup, obj: bpy.types.Object) -> Matrix:
    """Where the panorama shows `obj`: the matrix stored by its relocation, else where it is."""
    stored = relocated_matrix(settings, obj.name)
    return obj.matrix_world.copy() if stored is None else stored


def to_photographed(obj: bpy.types.Object, photographed: Matrix) -> np.ndarray | None:
    """(4, 4) world transform from where `obj` is now to its photographed matrix; None when it
    is there (exactly: no rounding through an inverse)."""
    current, wanted = np.array(obj.matrix_world, dtype=np.float64), np.array(photographed, dtype=np.float64)
    return None if np.array_equal(current, wanted) else wanted @ np.linalg.inv(current)


def _earlier(settings: bpy.types.PropertyGroup, target: str) -> list:
    """The list's entries of other objects that have a result."""
    return [r for r in settings.removals if r.object_name != target and r.image is not None]


def engine_scene(scene: bpy.types.Scene, target: str, photographed: Matrix | None = None) -> SceneData:
    """The scene as the engine must see it for a run on `target`: earlier removed objects gone
    from the room (`composition.without_objects`), relocated ones at their new place, and
    `target` where the panorama shows it; the panorama's pixels deferred."""
    from ...addon.composition import without_objects

    return without_objects(_photographed_scene(scene, target, photographed), _removed_before(scene.dimred, target))


def _photographed_scene(scene: bpy.types.Scene, target: str, photographed: Matrix | None = None) -> SceneData:
    """The whole room with `target` where the panorama shows it (`photographed`, by default
    `photographed_matrix`: also when an earlier relocation of it has moved it since), relocated
    objects at their new place; the panorama's pixels deferred."""
    from ...addon.blender import reader

    settings = scene.dimred
    scene_data = reader.read_scene(scene, center=probe_center(settings), defer_file=True)
    obj = scene.objects[target]
    if photographed is None:
        photographed = photographed_matrix(settings, obj)
    return _placed(scene_data, target, to_photographed(obj, photographed))


def _removed_before(settings: bpy.types.PropertyGroup, target: str) -> list[str]:
    """The objects removed (not relocated) before a run on `target`."""
    return [r.object_name for r in _earlier(settings, target) if r.kind == 'REMOVE']


def active() -> RemovalSession | None:
    """The session that is computing now, if any."""
    return next((s for s in _running if s.worker is not None and not s.done), None)


def stop_all() -> None:
    """Cancel and join every running worker (file load, unregister, exit)."""
    for session in list(_running):
        session.stop()


@bpy.app.handlers.persistent
def _stop_on_load(*_args) -> None:
    stop_all()


atexit.register(stop_all)


def register() -> None:
    if _stop_on_load not in bpy.app.handlers.load_pre:
        bpy.app.handlers.load_pre.append(_stop_on_load)


def unregister() -> None:
    stop_all()
    if _stop_on_load in bpy.app.handlers.load_pre:
        bpy.app.handlers.load_pre.remove(_stop_on_load)


@dataclass
class RemovalSession:
    scene_name: str
    world_name: str
    object_name: str
    request: RemovalRequest
    pack: bool
    relative: bool  # the output folder is given relative to the .blend
    photographed: Matrix  # the object's world matrix where the panorama shows it
    temporary_folder: str = ""  # files of this run only: packed results, earlier packed differences
    diagnostics_path: str = ""  # where the diagnostics picture goes beside the difference ("": nowhere)
    worker: Worker | None = None
    done: bool = False
    stage: str = "starting"
    fraction: float = 0.0
    message: str = ""  # the result's one line (info or error)
    ok: bool = False
    warnings: list[str] = field(default_factory=list)  # about the removal order, added to the report
    tick_seconds: list[float] = field(default_factory=list)  # main-thread time per tick

    # -- main thread: gather ------------------------------------------------------------
    @classmethod
    def begin(cls, context: bpy.types.Context, move: Move | None = None,
              photographed: Matrix | None = None) -> RemovalSession:
        """Check the input and read the scene; DimredError says what is wrong (nothing changed).

        With `move`, the run relocates the marked object instead of removing it, from
        `photographed` (its world matrix where the panorama shows it; by default
        `photographed_matrix`)."""
        from ...addon import memory
        from ...addon.blender import reader
        from ...addon.blender.mask_reader import mask_of_image
        from ...addon.relocation.fixedview import check_move
        from ...addon.run.job import RemovalRequest

        if active() is not None:
            raise DimredError("A removal is already running: wait for it or cancel it")
        if move is not None:
            check_move(move)
        scene = context.scene
        settings, world = scene.dimred, scene.world
        if world is None:
            raise DimredError("The scene has no World: light it with the panorama first")
        if settings.target is None:
            raise DimredError("Mark the object to remove first")
        target = settings.target.name
        pack = settings.storage == 'PACK'
        folder = "" if pack else output_folder(settings)
        world_layer.world_nodes(world)  # refuses a world the layer cannot be added to, before the work
        earlier = _earlier(settings, target)
        # Packed results and the earlier packed differences go to files the worker can read.
        own = _own(settings, target)
        shown = [r.image for r in earlier] + [own]
        packed = any(image is not None and image.packed_file is not None for image in shown)
        scratch = tempfile.mkdtemp(prefix="dimred-") if pack or packed else ""
        if pack:
            folder = scratch
        try:
            reader.check_object(scene, target)
            # Refused before any work when the panorama cannot fit (the size from its header).
            size = reader.panorama_size(scene)
            memory.check_fits(*size, quality=settings.quality,
                              working_width=settings.overrides().get("working_width"))
            mask = None if settings.mask_image is None else mask_of_image(settings.mask_image, size)
            names = settings.surface_names()
            for name in names:
                reader.check_object(scene, name, purpose="used as a target surface")
            if photographed is None:
                photographed = photographed_matrix(settings, scene.objects[target])
            # The worker composes this run with the earlier ones (`addon.composition.on_earlier`):
            # their objects leave the geometry, their differences are added to the panorama,
            # whose shapes are checked against the panorama's there, where it is read.
            base = tuple(_layer_source(r.image, os.path.join(scratch, f"earlier_{i}.exr"))
                         for i, r in enumerate(earlier))
            previous = _layer_source(own, os.path.join(scratch, "previous.exr")) if own is not None else None
            request = RemovalRequest(
                scene=_photographed_scene(scene, target, photographed), object_name=target, planes=names,
                quality=settings.quality, base=base, removed=tuple(_removed_before(settings, target)),
                own_path=os.path.join(folder, own_filename(world, target)),
                layer_path=os.path.join(folder, layer_filename(world)), overrides=settings.overrides(), move=move,
                previous=previous, cache_folder=warmup.folder(), mask=mask, align=settings.align_first,
                fit_height=settings.fit_height,
            )
        except BaseException:
            if scratch:
                shutil.rmtree(scratch, ignore_errors=True)
            raise
        diagnostics = "" if pack else os.path.join(folder, own_filename(world, target, "diagnostics.png"))
        index = _index(settings, target)
        later = [r.object_name for r in settings.removals[index + 1:]] if index >= 0 else []
        warnings = [(f"'{', '.join(later)}' were removed after '{target}' with it still in place: "
                     "remove them again for the most accurate result")] if later else []
        return cls(scene_name=scene.name, world_name=world.name, object_name=target, request=request, pack=pack,
                   relative=settings.output_dir.strip().startswith("//") and not pack, photographed=photographed,
                   temporary_folder=scratch, warnings=warnings, diagnostics_path=diagnostics)

    # -- computing ------------------------------------------------------------------------
    def run_here(self, context: bpy.types.Context) -> bool:
        """Compute on this thread and apply; True on success (`message` says what happened)."""
        from ...addon.callbacks import NO_CALLBACKS

        try:
            computed = self._task()(NO_CALLBACKS)
        except DimredError as error:
            return self._fail(context, str(error))
        return self._apply(context, computed)

    def start(self) -> None:
        """Compute in a worker thread; `tick` polls it."""
        self.worker = Worker(self._task()).start()
        _running.append(self)

    def _task(self) -> Callable[[RunCallbacks], Computed]:
        """The run as a function of its callbacks: first waiting for the small copy of the
        panorama if a thread is making it (its first preview needs it, and reading the file
        meanwhile would read it twice); then the diagnostics picture, staged beside the
        difference when that goes to a file."""
        from ...addon.io.exr import write_png
        from ...addon.run.job import run

        request, path = self.request, self.diagnostics_path
        warming = warmup.running(request.scene.hdri_path) if request.scene.hdri is None else None

        def task(callbacks: RunCallbacks) -> Computed:
            while warming is not None and not warming.join(WAIT_INTERVAL):
                callbacks.check()
            outcome = run(request, callbacks)
            picture = pictures.diagnostics_picture(outcome.seen)
            if picture is not None and path:
                try:
                    outcome.staged.write(path, lambda temporary: write_png(temporary, picture.image))
                except OSError as error:
                    outcome.staged.discard()
                    raise DimredError(f"cannot write the diagnostics picture: {error.strerror or error}") from None
            return Computed(outcome, picture)

        return task

    def tick(self, context: bpy.types.Context) -> str:
        """Poll the worker: 'RUNNING', 'FINISHED' or 'CANCELLED' (failed or cancelled)."""
        started = time.perf_counter()
        try:
            update = self.worker.poll()
            self.stage, self.fraction = update.stage, update.fraction
            if update.preview is not None and not self.worker.cancelled:
                self._show_preview(context, update.preview)
            if not update.finished:
                return 'RUNNING'
            self.done = True
            self._forget()
            if isinstance(update.error, (DimredError, Cancelled)):
                self._fail(context, str(update.error))
            elif update.error is not None:
                self._fail(context, f"The {self.verb} failed: {type(update.error).__name__}: {update.error}")
            else:
                self._apply(context, update.result)
            return 'FINISHED' if self.ok else 'CANCELLED'
        finally:
            self.tick_seconds.append(time.perf_counter() - started)

    def cancel(self, context: bpy.types.Context | None = None) -> None:
        """Stop the worker, wait for it, and put the world back as it was."""
        self.stop()
        if not self.done:
            self.done = True
            self._fail(context, str(Cancelled()))

    def stop(self) -> None:
        if self.worker is not None:
            self.worker.stop(STOP_TIMEOUT)
        self._forget()

    @property
    def verb(self) -> str:
        return "removal" if self.request.move is None else "relocation"

    # -- main thread: show and apply ----------------------------------------------------------
    def _world(self) -> bpy.types.World | None:
        return bpy.data.worlds.get(self.world_name)

    def _show_preview(self, context: bpy.types.Context, preview: Preview) -> None:
        world = self._world()
        if world is None:
            return
        color = _preview_image(PREVIEW_IMAGE, preview.width, preview.height, preview.color)
        mask = _preview_image(PREVIEW_MASK_IMAGE, preview.width, preview.height, preview.mask)
        world_layer.show_preview(world, color, mask)
        world.update_tag()
        _redraw(context)

    def _apply(self, context: bpy.types.Context, computed: Computed) -> bool:
        outcome = computed.outcome
        world = self._world()
        scene = bpy.data.scenes.get(self.scene_name)
        if world is None or scene is None:
            outcome.staged.discard()
            return self._fail(context, f"The scene or world was deleted while the {self.verb} ran")
        try:
            outcome.staged.commit()
        except OSError as error:
            outcome.staged.discard()
            return self._fail(context, f"Could not write the difference image: {error}")
        request = self.request
        own = _load(request.own_path, os.path.basename(request.own_path)[:-4], self.relative, self.pack)
        layer = _load(request.layer_path, os.path.basename(request.layer_path)[:-4], self.relative, self.pack)
        if self.temporary_folder:
            shutil.rmtree(self.temporary_folder, ignore_errors=True)
        world_layer.add_layer(world, layer)  # in place of the preview
        _drop_preview()
        settings = scene.dimred
        index = _index(settings, self.object_name)
        entry = settings.removals[index] if index >= 0 else settings.removals.add()
        entry.object_name, entry.image = self.object_name, own
        report = dict(outcome.report)
        self._place(scene, entry, report)
        report.setdefault("warnings", []).extend(self.warnings)
        report["layer"] = [r.object_name for r in settings.removals]
        settings.last_report = json.dumps(report)
        settings.photo_fit = photo_fit(self.object_name, report.get("segmentation"), report.get("alignment"))
        if computed.picture is not None:
            pictures.show_diagnostics(computed.picture)
        self.ok = True
        where = "packed into the .blend" if self.pack else f"wrote {request.layer_path}"
        done = f"Removed '{self.object_name}'" if request.move is None else (
            f"Relocated '{self.object_name}' ({move_summary(report['relocation'])})")
        self.message = f"{done}: {report_summary(report)}; {where}"
        _redraw(context)
        return True

    def _place(self, scene: bpy.types.Scene, entry: bpy.types.PropertyGroup, report: dict) -> None:
        """Record the move on the entry and put the object where the new panorama shows it:
        moved from its photographed place, or back there when a relocated object is removed;
        the photographed place itself corrected first where the run aligned it to the photo."""
        move = self.request.move
        relocated_before = entry.kind == 'RELOCATE'
        entry.kind = 'REMOVE' if move is None else 'RELOCATE'
        alignment = report.get("alignment") or {}
        photographed = self.photographed
        if alignment.get("applied"):
            correction = Matrix(alignment["matrix"])
            photographed = correction @ photographed
            scene.dimred.correct_marked(self.object_name, correction)
        elif move is None and not relocated_before:
            return
        placed = photographed
        if move is not None:
            entry.yaw, entry.distance_scale = move.yaw, move.distance_scale
            entry.set_photographed_matrix(photographed)
            placed = Matrix(report["relocation"]["matrix"]) @ photographed
        obj = scene.objects.get(self.object_name)
        if obj is not None:
            obj.matrix_world = placed

    def _fail(self, context: bpy.types.Context | None, message: str) -> bool:
        """Put the world back as it was before this session and keep `message`."""
        world = self._world()
        if world is not None:
            world_layer.remove_preview(world)
        _drop_preview()
        if self.temporary_folder:
            shutil.rmtree(self.temporary_folder, ignore_errors=True)
        self.ok, self.message = False, message
        if context is not None:
            _redraw(context)
        return False

    def _forget(self) -> None:
        if self in _running:
            _running.remove(self)


@dataclass(frozen=True)
class Computed:
    """What the worker hands back: the run's outcome and its diagnostics picture."""

    outcome: RemovalOutcome
    picture: pictures.Picture | None


def photo_fit(object_name: str, segmentation: dict | None, alignment: dict | None) -> str:
    """`scene.dimred.photo_fit`: how the proxy of `object_name` fitted the photograph, as JSON."""
    return json.dumps({"object": object_name, "segmentation": segmentation, "alignment": alignment})


def report_summary(report: dict) -> str:
    """One line about a run's report dict (fields per the command line's report.json)."""
    total = report.get("seconds", {}).get("total")
    parts = [f"{total:.1f} s" if isinstance(total, (int, float)) else "done"]
    for key, label in (("skipped", "stages skipped"), ("warnings", "warnings")):
        if report.get(key):
            parts.append(f"{len(report[key])} {label}")
    return ", ".join(parts)


def move_summary(relocation: dict) -> str:
    """The move of a report's `relocation` entry in a few words."""
    return (f"yaw {relocation['yaw']:.1f}°, distance ×{relocation['distance_scale']:.2f}, "
            f"view elevation {relocation['elevation_change']:+.1f}°")


def _placed(scene: SceneData, name: str, transform: np.ndarray | None) -> SceneData:
    """`scene` with the triangles of object `name` moved by the (4, 4) world `transform`."""
    from ...addon.relocation.fixedview import apply

    if transform is None:
        return scene
    triangles = scene.triangles.copy()
    mine = scene.tri_object == scene.object_index(name)
    triangles[mine] = apply(transform, triangles[mine])
    return replace(scene, triangles=triangles)


def _index(settings: bpy.types.PropertyGroup, object_name: str) -> int:
    return next((i for i, r in enumerate(settings.removals) if r.object_name == object_name), -1)


def _own(settings: bpy.types.PropertyGroup, object_name: str) -> bpy.types.Image | None:
    """The own difference of an earlier run on `object_name`, which the world shows now."""
    index = _index(settings, object_name)
    return settings.removals[index].image if index >= 0 else None


def _layer_source(image: bpy.types.Image, unpacked: str) -> Layer:
    """An earlier removal's difference as the worker reads it: its EXR file (a packed one
    written to the path `unpacked` first), or, for an image that is not its file, its pixels."""
    if image.packed_file is not None:
        with open(unpacked, "wb") as file:
            file.write(image.packed_file.data)
        return unpacked
    path = os.path.normpath(bpy.path.abspath(image.filepath, library=image.library))
    if image.source == 'FILE' and not image.is_dirty and os.path.isfile(path):
        return path
    return world_layer.image_rgb(image)


def _load(path: str, name: str, relative: bool, pack: bool) -> bpy.types.Image:
    # A folder given relative to the .blend stays relative, so the file can move with it.
    image = world_layer.load_difference_image(bpy.path.relpath(path) if relative else path, name)
    if pack:
        image.pack()
    return image


def _preview_image(name: str, width: int, height: int, pixels: np.ndarray) -> bpy.types.Image:
    """The preview image `name` of that size (made anew for another size) holding `pixels`."""
    image = bpy.data.images.get(name)
    if image is not None and tuple(image.size) != (width, height):
        bpy.data.images.remove(image)
        image = None
    if image is None:
        image = bpy.data.images.new(name, width, height, alpha=True, float_buffer=True)
        image.colorspace_settings.name = world_layer.DIFFERENCE_COLORSPACE
    image.pixels.foreach_set(pixels)
    image.update()
    return image


def _drop_preview() -> None:
    for name in (PREVIEW_IMAGE, PREVIEW_MASK_IMAGE):
        image = bpy.data.images.get(name)
        if image is not None:
            bpy.data.images.remove(image)


def _redraw(context: bpy.types.Context | None) -> None:
    screen = getattr(context, "screen", None) if context is not None else None
    for area in (screen.areas if screen is not None else ()):
        if area.type in {'VIEW_3D', 'PROPERTIES', 'NODE_EDITOR', 'IMAGE_EDITOR'}:
            area.tag_redraw()
