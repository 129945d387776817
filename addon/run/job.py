"""One removal (or relocation) as the Blender operator runs it: plain data in, staged files and
previews out (no bpy).

The operator gathers a `RemovalRequest` on the main thread and runs `run` either in a worker
thread or, in background mode, directly. A request with a `move` relocates the object (removal
at the photographed place, insertion at the moved one) and is otherwise handled the same; the
artist's mask and Align to Photo (`align`, `fit_height`) go to the engine as they are, and the
outcome keeps the object as the photograph showed it, for the diagnostics picture.
Removals compose (`addon.composition`): the request names the objects removed before
(`removed`) and their differences (`base`); the engine works on HDRI + base without those
objects, and the world layer shows base + this run's difference. Files
are written under temporary names next to their final paths and only `Staged.commit` (on the
main thread, once the run is accepted) renames them into place, so a cancelled or failed run
leaves earlier results as they were.

Previews are small whatever the panorama's size (`preview`), so showing one costs the main
thread milliseconds. The first comes from small copies of the input files before the panorama
itself is read (`quick_preview`), the next ones are the engine's, resampled here in the worker.
"""
from __future__ import annotations

import contextlib
import functools
import os
import secrets
import shutil
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field, replace

import numpy as np

from ..callbacks import NO_CALLBACKS, RunCallbacks
from ..composition import on_earlier
from ..errors import DimredError
from ..geometry.mesh import to_probe_frame
from ..io.exr import read_exr, write_exr
from ..pipeline import relocate_object, remove_object
from ..quality import DEFAULT_QUALITY
from ..relocation.fixedview import Move
from ..run_memory import run_memory
from ..scene import SceneData
from ..segmentation.seen import SeenObject
from ..segmentation.user_mask import UserMask
from . import small_copy
from .preview import Previews

Layer = str | np.ndarray  # an EXR file's path (read in the worker) or (H, W, 3) float32 pixels


@dataclass
class RemovalRequest:
    scene: SceneData  # hdri None: read from scene.hdri_path in the worker, off the main thread
    object_name: str
    planes: tuple[str, ...] = ()
    quality: str = DEFAULT_QUALITY
    base: tuple[Layer, ...] = ()  # the own differences of the objects removed (or relocated) before
    removed: tuple[str, ...] = ()  # the objects removed before, left out of the geometry
    previous: Layer | None = None  # this object's own difference from a run before (the world shows it)
    own_path: str = ""  # where this removal's own difference goes
    layer_path: str = ""  # where base + own difference (what the world shows) goes
    overrides: dict = field(default_factory=dict)  # engine parameters that replace the preset's
    move: Move | None = None  # relocate the object by this move instead of removing it
    cache_folder: str = ""  # where small copies of the files are kept between runs ("": nowhere)
    mask: UserMask | None = None  # the artist's additions to and cuts from the region filled
    align: bool = False  # fit the proxy's pose to the photograph first (Align to Photo)
    fit_height: bool = False  # ... its support's height instead of its scale


@dataclass
class Staged:
    """Files written under temporary names, waiting for `commit` or `discard`."""

    moves: list[tuple[str, str]] = field(default_factory=list)  # (temporary, final)

    def write(self, path: str, writer: Callable[[str], object]) -> str:
        """`writer(temporary)` the file that `commit` will move to `path`; the temporary name."""
        os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
        folder, name = os.path.split(path)
        temporary = os.path.join(folder, f".{name}.{secrets.token_hex(4)}.staged{os.path.splitext(name)[1]}")
        self.moves.append((temporary, path))
        writer(temporary)
        return temporary

    def commit(self) -> None:
        for temporary, final in self.moves:
            os.replace(temporary, final)
        self.moves = []

    def discard(self) -> None:
        for temporary, _ in self.moves:
            with contextlib.suppress(FileNotFoundError):
                os.unlink(temporary)
        self.moves = []


@dataclass
class RemovalOutcome:
    report: dict
    staged: Staged  # this removal's own difference and the layer (base + own), to commit
    seen: SeenObject | None = None  # the object as the photograph showed it (the diagnostics picture's)


def loaded(scene: SceneData) -> SceneData:
    """`scene` with its panorama read from `hdri_path` if the reader deferred it."""
    if scene.hdri is not None:
        return scene
    if not scene.hdri_path:
        raise DimredError("the scene has no panorama pixels and no file to read them from")
    return replace(scene, hdri=read_exr(scene.hdri_path))


def run(request: RemovalRequest, callbacks: RunCallbacks = NO_CALLBACKS) -> RemovalOutcome:
    """Remove (or relocate) the requested object; `callbacks.preview` gets `preview.Preview`s:
    a quick fill first, then the engine's."""
    # Reading the panorama and writing the layer allocate as much as the removal does.
    with run_memory():
        return _run(request, callbacks)


def _run(request: RemovalRequest, callbacks: RunCallbacks) -> RemovalOutcome:
    wanted = callbacks.preview is not None
    _progress(callbacks, "preview")
    panorama, base = _cached(request) if wanted else (None, [None] * len(request.base))
    previews = None
    if panorama is not None and None not in base:
        previews = _quick(request, _small_input(panorama, base), callbacks)
    callbacks.check()
    _progress(callbacks, "reading")
    scene, small = _engine_input(request, callbacks, panorama, base, small=wanted)
    if previews is None and small is not None:
        previews = _quick(request, small, callbacks)
    engine_callbacks = callbacks
    if previews is not None:
        if request.previous is not None:
            previous = (_copy(request.previous, request.cache_folder)
                        or small_copy.of_image(_pixels(request.previous, scene.hdri.shape)))
            previews = replace(previews, previous=small_copy.resample(previous.image, *previews.mask.shape))
        engine_callbacks = callbacks.mapped_preview(previews.of_difference)
    engine = remove_object if request.move is None else functools.partial(relocate_object, move=request.move)
    result = engine(scene, request.object_name, planes=request.planes, quality=request.quality,
                    callbacks=engine_callbacks, mask=request.mask, align=request.align,
                    fit_height=request.fit_height, **request.overrides)
    del scene  # the panorama: the layer needs only the difference and the base
    difference, report, seen = result.difference, result.report, result.seen
    del result
    callbacks.check()
    _progress(callbacks, "writing", 1.0)
    return RemovalOutcome(report=report, staged=_write(request, difference), seen=seen)


def _progress(callbacks: RunCallbacks, stage: str, fraction: float = 0.0) -> None:
    if callbacks.progress is not None:
        callbacks.progress(stage, fraction)


def _quick(request: RemovalRequest, panorama: np.ndarray, callbacks: RunCallbacks) -> Previews:
    """The run's previews on the small `panorama`, the quick fill shown."""
    scene = request.scene
    triangles = None
    if request.object_name in scene.object_names:
        mine = scene.tri_object == scene.object_index(request.object_name)
        triangles = to_probe_frame(scene.triangles[mine], scene.center, scene.rotation)
    previews, first = Previews.quick(panorama, triangles)
    if first is not None:
        callbacks.show(first)
    return previews


def _copy(layer: Layer, folder: str) -> small_copy.SmallCopy | None:
    """The small copy of a file or pixels at hand without reading a file, if there is one."""
    if isinstance(layer, np.ndarray):
        return small_copy.of_image(layer)
    return small_copy.cached(layer, folder) if folder else None


def _cached(request: RemovalRequest) -> tuple[small_copy.SmallCopy | None, list[small_copy.SmallCopy | None]]:
    """The small copies at hand, the panorama's and each earlier result's (None where missing)."""
    scene, folder = request.scene, request.cache_folder
    panorama = _copy(scene.hdri if scene.hdri is not None else scene.hdri_path, folder)
    return panorama, [_copy(layer, folder) for layer in request.base]


def _small_input(panorama: small_copy.SmallCopy, base: list[small_copy.SmallCopy]) -> np.ndarray:
    """The small copy of HDRI + base."""
    total = panorama.image
    for copy in base:
        # Copies of files of another size would be resampled: the full read refuses them later.
        total = total + small_copy.resample(copy.image, *panorama.image.shape[:2])
    return total


def _engine_input(request: RemovalRequest, callbacks: RunCallbacks, panorama: small_copy.SmallCopy | None,
                  base: list[small_copy.SmallCopy | None], *, small: bool) -> tuple[SceneData, np.ndarray | None]:
    """The scene composed with the earlier results (`composition.on_earlier`: read, their
    differences added to the panorama, their objects left out) and, if `small`, the small copy
    of that panorama (from the small copies at hand where there are)."""
    scene = loaded(request.scene)
    if small and panorama is None:
        panorama = small_copy.of_image(scene.hdri)
        if request.cache_folder:
            small_copy.store(scene.hdri_path, panorama, request.cache_folder)
    callbacks.check()
    copies = []

    def earlier() -> Iterator[np.ndarray]:
        for layer, copy in zip(request.base, base, strict=True):
            image = _pixels(layer, scene.hdri.shape)
            if small:
                copies.append(copy or small_copy.of_image(image))
            yield image
            del image
            callbacks.check()

    # A panorama read here is this run's own: the differences are added into it, not a copy.
    composed = on_earlier(scene, earlier(), request.removed, own=request.scene.hdri is None)
    return composed, _small_input(panorama, copies) if small else None


def _pixels(layer: Layer, shape: tuple[int, ...]) -> np.ndarray:
    """The pixels of an earlier removal's difference, checked against the panorama's `shape`."""
    image = read_exr(layer) if isinstance(layer, str) else layer
    if image.shape != shape:
        raise DimredError(
            f"the earlier removals' difference is {image.shape[1]}x{image.shape[0]} but the panorama is "
            f"{shape[1]}x{shape[0]}: clear them and remove again"
        )
    return image


def _write(request: RemovalRequest, difference: np.ndarray) -> Staged:
    """Stage this removal's own difference, then the layer (the base added to the same array,
    or, without a base, the own file copied: the encoding is the slow part), and keep the own
    difference's small copy for the runs that will build on it."""
    staged = Staged()
    try:
        own = ""
        if request.own_path:
            own = staged.write(request.own_path, lambda temporary: write_exr(temporary, difference))
            if request.cache_folder:
                small_copy.store(request.own_path, small_copy.of_image(difference), request.cache_folder,
                                 stat=os.stat(own))
        if request.layer_path and own and not request.base:
            staged.write(request.layer_path, lambda temporary: shutil.copyfile(own, temporary))
        elif request.layer_path:
            # In place: the engine's array is no one else's, and the own file is written.
            for layer in request.base:
                difference += _pixels(layer, difference.shape)
            staged.write(request.layer_path, lambda temporary: write_exr(temporary, difference))
    except OSError as error:
        staged.discard()
        raise DimredError(f"cannot write the difference image: {error.strerror or error}") from None
    except BaseException:
        staged.discard()
        raise
    return staged
