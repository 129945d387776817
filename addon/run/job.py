"""One removal (or relocation) as the Blender operator runs it: plain data in, staged files out
(no bpy).

The operator gathers a `RemovalRequest` on the main thread and runs `run` either in a worker
thread or, in background mode, directly. A request with a `move` relocates the object (removal
at the photographed place, insertion at the moved one) and is otherwise handled the same.
Removals compose: the request carries the difference of the objects removed before (`base`),
the engine works on HDRI + base, and the world layer shows base + this run's difference. Files
are written under temporary names next to their final paths and only `Staged.commit` (on the
main thread, once the run is accepted) renames them into place, so a cancelled or failed run
leaves earlier results as they were.
"""
from __future__ import annotations

import contextlib
import functools
import os
import secrets
from dataclasses import dataclass, field, replace

import numpy as np

from ..callbacks import NO_CALLBACKS, RunCallbacks
from ..errors import DimredError
from ..io.exr import read_exr, write_exr
from ..pipeline import relocate_object, remove_object
from ..quality import DEFAULT_QUALITY
from ..relocation.fixedview import Move
from ..scene import SceneData


@dataclass
class RemovalRequest:
    scene: SceneData  # hdri None: read from scene.hdri_path in the worker, off the main thread
    object_name: str
    planes: tuple[str, ...] = ()
    quality: str = DEFAULT_QUALITY
    base: np.ndarray | None = None  # (H, W, 3) difference of the objects removed before
    own_path: str = ""  # where this removal's own difference goes
    layer_path: str = ""  # where base + own difference (what the world shows) goes
    overrides: dict = field(default_factory=dict)  # engine parameters that replace the preset's
    move: Move | None = None  # relocate the object by this move instead of removing it


@dataclass
class Staged:
    """Files written under temporary names, waiting for `commit` or `discard`."""

    moves: list[tuple[str, str]] = field(default_factory=list)  # (temporary, final)

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


def loaded(scene: SceneData) -> SceneData:
    """`scene` with its panorama read from `hdri_path` if the reader deferred it."""
    if scene.hdri is not None:
        return scene
    if not scene.hdri_path:
        raise DimredError("the scene has no panorama pixels and no file to read them from")
    return replace(scene, hdri=read_exr(scene.hdri_path))


def blender_pixels(image: np.ndarray) -> np.ndarray:
    """(H, W, 3) top row first -> the flat RGBA float32 buffer `Image.pixels` takes (bottom row first)."""
    h, w = image.shape[:2]
    rgba = np.ones((h, w, 4), dtype=np.float32)
    rgba[..., :3] = image[::-1]
    return rgba.ravel()


def run(request: RemovalRequest, callbacks: RunCallbacks = NO_CALLBACKS) -> RemovalOutcome:
    """Remove (or relocate) the requested object; `callbacks.preview` gets the layer (base +
    difference so far) as `blender_pixels` buffers, ready for the main thread to show."""
    scene = loaded(request.scene)
    base = request.base
    if base is not None:
        if base.shape != scene.hdri.shape:
            raise DimredError(
                f"the earlier removals' difference is {base.shape[1]}x{base.shape[0]} but the panorama is "
                f"{scene.hdri.shape[1]}x{scene.hdri.shape[0]}: clear them and remove again"
            )
        scene = replace(scene, hdri=(scene.hdri + base).astype(np.float32))
    engine_callbacks = callbacks.mapped_preview(
        lambda difference: blender_pixels(difference if base is None else difference + base))
    engine = remove_object if request.move is None else functools.partial(relocate_object, move=request.move)
    result = engine(scene, request.object_name, planes=request.planes, quality=request.quality,
                    callbacks=engine_callbacks, **request.overrides)
    layer = result.difference if base is None else (result.difference + base).astype(np.float32)
    callbacks.check()
    staged = Staged()
    try:
        for path, image in ((request.own_path, result.difference), (request.layer_path, layer)):
            if path:
                os.makedirs(os.path.dirname(path) or ".", exist_ok=True)
                folder, name = os.path.split(path)
                temporary = os.path.join(folder, f".{name}.{secrets.token_hex(4)}.staged.exr")
                write_exr(temporary, image)
                staged.moves.append((temporary, path))
    except OSError as error:
        staged.discard()
        raise DimredError(f"cannot write the difference image: {error.strerror or error}") from None
    except BaseException:
        staged.discard()
        raise
    return RemovalOutcome(report=result.report, staged=staged)
