"""Fixtures of the Blender-side tests: the repository imported the way Blender imports the
installed extension, a fresh Blender session, the tiny room saved as a .blend, and a Cycles
render of the world as a lat-long panorama.

Blender imports an extension as a package (`bl_ext.<repo>.diminished_reality`) whose modules
use relative imports; here the repository root becomes the package `diminished_reality`. Its
engine, `diminished_reality.addon`, is the very package the engine tests import as `addon`
(see `EngineAlias`), so one process holds one copy of every engine module.
"""
from __future__ import annotations

import importlib
import importlib.abc
import importlib.machinery
import importlib.util
import sys
from pathlib import Path
from types import ModuleType

import numpy as np
import pytest

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = "diminished_reality"
ENGINE = "addon"


class EngineAlias(importlib.abc.MetaPathFinder, importlib.abc.Loader):
    """Imports `diminished_reality.addon[.X]` as the module object `addon[.X]`.

    Without it the extension's relative imports would load a second copy of every engine module
    from the same files, so an engine exception raised inside an operator would be a different
    class from the one a test imported from `addon.errors`, and a test patching `addon.X` would
    not patch what the operators call.
    """

    prefix = f"{PACKAGE}.{ENGINE}"

    def __init__(self) -> None:
        self._engine_specs: dict[str, importlib.machinery.ModuleSpec] = {}

    def find_spec(self, fullname: str, path=None, target=None) -> importlib.machinery.ModuleSpec | None:
        if fullname != self.prefix and not fullname.startswith(self.prefix + "."):
            return None
        real = importlib.util.find_spec(self._engine_name(fullname))
        if real is None:
            return None
        return importlib.util.spec_from_loader(fullname, self, is_package=real.submodule_search_locations is not None)

    def create_module(self, spec: importlib.machinery.ModuleSpec) -> ModuleType:
        module = importlib.import_module(self._engine_name(spec.name))
        self._engine_specs[spec.name] = module.__spec__
        return module

    def exec_module(self, module: ModuleType) -> None:
        """Nothing to run (the engine module already ran); the import system has just set the
        module's `__spec__` to the alias's, so put back the engine's own (its relative imports,
        `importlib.reload` and pickling go by it)."""
        module.__spec__ = self._engine_specs.pop(module.__spec__.name)

    def _engine_name(self, alias: str) -> str:
        return ENGINE + alias[len(self.prefix):]


def import_extension() -> ModuleType:
    """The repository root as the package `diminished_reality` (imported once per process),
    its engine aliased to `addon`."""
    if not any(isinstance(finder, EngineAlias) for finder in sys.meta_path):
        sys.meta_path.insert(0, EngineAlias())
    if PACKAGE not in sys.modules:
        spec = importlib.util.spec_from_file_location(
            PACKAGE, ROOT / "__init__.py", submodule_search_locations=[str(ROOT)]
        )
        module = importlib.util.module_from_spec(spec)
        sys.modules[PACKAGE] = module
        spec.loader.exec_module(module)
    return sys.modules[PACKAGE]


@pytest.fixture(scope="session")
def extension() -> ModuleType:
    return import_extension()


@pytest.fixture
def registered(extension: ModuleType):
    """The add-on registered for one test, on a fresh empty Blender session."""
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    extension.register()
    try:
        yield extension
    finally:
        extension.unregister()


@pytest.fixture
def fresh_blender():
    """An empty Blender session (factory settings, no objects) for a test that builds a scene."""
    import bpy

    bpy.ops.wm.read_factory_settings(use_empty=True)
    yield bpy
    bpy.ops.wm.read_factory_settings(use_empty=True)


@pytest.fixture
def render_world(tmp_path: Path):
    """A function that renders the current scene's world with Cycles from `origin` through an
    equirectangular panoramic camera and returns (height, width, 3) float32, top row first.

    One sample with a 0.01 px Blackman-Harris filter point-samples each pixel's centre
    direction; the camera rotation (90, 0, -90) degrees makes the render's pixel directions
    those of `addon.geometry.latlong.pixel_directions`. Keep sizes tiny: the machine is shared.
    """
    from tests.blender import tiny_scene

    def render(width: int, height: int, origin: tuple[float, float, float] = (0.0, 0.0, 0.0)) -> np.ndarray:
        return tiny_scene.render_world(width, height, origin, tmp_path / "render.exr")

    return render


@pytest.fixture
def panorama_world(fresh_blender):
    """A function that makes the scene's world show `image` through an Environment Texture
    (Closest interpolation, so a render shows single texels); with `mapping` = (type,
    rotation, scale) a Texture Coordinate > Mapping chain feeds its vector. Returns the world's
    node tree."""
    bpy = fresh_blender

    def build(image, mapping: tuple[str, tuple, tuple] | None = None):
        world = bpy.data.worlds.new("Probe")
        bpy.context.scene.world = world
        if world.node_tree is None:
            world.use_nodes = True  # Blender 4.x creates worlds without a node tree
        tree = world.node_tree
        tree.nodes.clear()
        output = tree.nodes.new("ShaderNodeOutputWorld")
        background = tree.nodes.new("ShaderNodeBackground")
        environment = tree.nodes.new("ShaderNodeTexEnvironment")
        environment.image = image
        environment.interpolation = 'Closest'
        tree.links.new(environment.outputs["Color"], background.inputs["Color"])
        tree.links.new(background.outputs["Background"], output.inputs["Surface"])
        if mapping is not None:
            kind, rotation, scale = mapping
            coordinates = tree.nodes.new("ShaderNodeTexCoord")
            node = tree.nodes.new("ShaderNodeMapping")
            node.vector_type = kind
            node.inputs["Rotation"].default_value = rotation
            node.inputs["Scale"].default_value = scale
            tree.links.new(coordinates.outputs["Generated"], node.inputs["Vector"])
            tree.links.new(node.outputs["Vector"], environment.inputs["Vector"])
        return tree

    return build


@pytest.fixture
def room(registered, tmp_path: Path) -> Path:
    """The tiny room saved as a .blend in tmp_path, with the box marked for removal (draft
    quality); returns the HDRI's path."""
    import bpy

    from tests.blender import tiny_scene

    hdri = tmp_path / "room.exr"
    tiny_scene.write_exr(hdri, tiny_scene.synthetic_hdri(64, 32))
    tiny_scene.build_scene(hdri)
    bpy.ops.wm.save_as_mainfile(filepath=str(tmp_path / "room.blend"))
    settings = bpy.context.scene.dimred
    settings.target = bpy.data.objects["Box"]
    settings.quality = "draft"
    return hdri


@pytest.fixture
def drive():
    """A function that ticks a started RemovalSession the way the modal operator's timer does,
    until it ends; returns its last state ('FINISHED' or 'CANCELLED')."""
    import time

    import bpy

    def run(session, poll_interval: float = 0.01, timeout: float = 300.0, on_tick=None) -> str:
        deadline = time.perf_counter() + timeout
        while time.perf_counter() < deadline:
            state = session.tick(bpy.context)
            if on_tick is not None:
                on_tick(session)
            if state != 'RUNNING':
                return state
            time.sleep(poll_interval)
        session.cancel(bpy.context)
        raise AssertionError("the run did not finish")

    return run
