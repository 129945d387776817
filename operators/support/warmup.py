"""What a run needs made ahead of it, in a background thread: the small copy of the world's
panorama, and the engine's modules imported.

A run's first preview needs a small copy of the panorama (`addon.run.small_copy`). Made from
the file at the start of the run, it would wait seconds for a large EXR to be read; so marking
an object to remove (or opening a file where one is marked) makes it then, and the run finds it
stored, or waits for the thread making it instead of reading the file a second time. Importing
the engine takes a tenth of a second too, which the first run would spend on the main thread.

The threads are kept in `_warming` by panorama file, so that a run can wait for the one making
its copy; they only write a cache file, so file load and exit need not wait for them.
"""
from __future__ import annotations

import importlib
import os

import bpy

from ...addon.errors import DimredError
from ...addon.run.worker import Worker
from . import world_layer

_warming: dict[str, Worker] = {}


def panorama_file(scene: bpy.types.Scene) -> str:
    """The EXR file the scene's world shows as it is on disk, '' when it shows something else."""
    world = scene.world
    try:
        image = world_layer.world_nodes(world)[0].image if world is not None else None
    except DimredError:  # a world that cannot be run on: the run says why
        return ""
    if image is None or image.source != 'FILE' or image.packed_file is not None or image.is_dirty:
        return ""
    path = os.path.normpath(bpy.path.abspath(image.filepath, library=image.library))
    return path if path.lower().endswith(".exr") and os.path.isfile(path) else ""


def folder() -> str:
    from ...addon.run.small_copy import default_folder

    return default_folder()


def warm(scene: bpy.types.Scene) -> None:
    """Start making what a run on `scene` needs unless it is under way."""
    path = panorama_file(scene)
    if running(path) is None:
        cache = folder()
        _warming[path] = Worker(lambda _callbacks: _prepare(path, cache), name="dimred-warmup").start()


def _prepare(path: str, cache: str) -> None:
    # The run's modules, imported here rather than on the main thread when it starts.
    for module in ("...addon.blender.reader", "...addon.run.job"):
        importlib.import_module(module, __package__)
    if path:
        from ...addon.run import small_copy

        small_copy.of_file(path, cache)


def running(path: str) -> Worker | None:
    """The thread preparing a run on the panorama file `path`, while it runs."""
    for key in [key for key, worker in _warming.items() if worker.join(0)]:
        del _warming[key]
    return _warming.get(path)


@bpy.app.handlers.persistent
def _warm_on_load(*_args) -> None:
    scene = bpy.context.scene
    if scene is not None and scene.dimred.target is not None:
        warm(scene)


def register() -> None:
    if _warm_on_load not in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.append(_warm_on_load)


def unregister() -> None:
    if _warm_on_load in bpy.app.handlers.load_post:
        bpy.app.handlers.load_post.remove(_warm_on_load)
