"""Registering the extension with the PyPI bpy: classes, settings, operators and their polls."""
from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import bpy
import pytest

OPERATORS = ("set_probe_center", "mark_remove", "mark_surface", "remove", "relocate", "cancel", "clear", "save_hdri")


def _operator_exists(name: str) -> bool:
    return hasattr(bpy.types, f"DIMRED_OT_{name}")


def test_register_and_unregister_twice(extension):
    for _ in range(2):
        extension.register()
        try:
            assert all(_operator_exists(name) for name in OPERATORS)
            assert hasattr(bpy.types.Scene, "dimred")
            assert hasattr(bpy.types, "DIMRED_PT_main")
        finally:
            extension.unregister()
        assert not any(_operator_exists(name) for name in OPERATORS)
        assert not hasattr(bpy.types.Scene, "dimred")
        assert not hasattr(bpy.types, "DIMRED_PT_main")


ENGINE_IMPORT_CHECK = """
import importlib.util, sys
spec = importlib.util.spec_from_file_location("dr", sys.argv[1], submodule_search_locations=[sys.argv[2]])
package = importlib.util.module_from_spec(spec)
sys.modules["dr"] = package
spec.loader.exec_module(package)
package.register()
print(sorted(name for name in sys.modules if name.startswith("dr.addon.")))
"""


def test_registration_leaves_the_engine_unimported():
    # Enabling the add-on must stay cheap: the engine loads when an operator or the command
    # runs. A fresh process, because other tests here have imported the engine already.
    root = Path(__file__).resolve().parents[2]
    result = subprocess.run(
        [sys.executable, "-c", ENGINE_IMPORT_CHECK, str(root / "__init__.py"), str(root)],
        capture_output=True, text=True,
    )
    assert result.returncode == 0, result.stderr
    # The error types, the run's callbacks, the worker thread and the quality presets (standard
    # library only) are all the operators need.
    assert result.stdout.strip().splitlines()[-1] == (
        "['dr.addon.callbacks', 'dr.addon.errors', 'dr.addon.quality', 'dr.addon.run', 'dr.addon.run.worker']")


def test_operators_and_settings(registered):
    for name in OPERATORS:
        operator = getattr(bpy.ops.dimred, name)
        rna = operator.get_rna_type()
        assert rna.name and rna.description, name
    relocate = bpy.ops.dimred.relocate.get_rna_type().properties
    assert relocate["yaw"].default == 0.0 and relocate["distance_scale"].default == 1.0

    settings = bpy.context.scene.dimred
    assert settings.quality == "balanced"
    quality = settings.bl_rna.properties["quality"]
    assert {item.identifier for item in quality.enum_items} == {"draft", "balanced", "final"}
    assert settings.output_dir == "//dimred/"
    assert settings.bl_rna.properties["probe_center"].subtype == 'XYZ_LENGTH'


def test_command_line_command_is_the_cli(registered):
    import diminished_reality

    # The bpy module cannot run `blender -c dimred`; the registered function delegates lazily.
    assert diminished_reality._cli_handle is not None
    assert diminished_reality._dimred_command.__module__ == "diminished_reality"


def _mesh(name: str) -> bpy.types.Object:
    obj = bpy.data.objects.new(name, bpy.data.meshes.new(name))
    bpy.context.scene.collection.objects.link(obj)
    return obj


def _activate(obj: bpy.types.Object | None) -> None:
    for other in bpy.context.scene.objects:
        other.select_set(False)
    bpy.context.view_layer.objects.active = obj
    if obj is not None:
        obj.select_set(True)


def test_poll_messages_say_why(registered):
    _activate(None)
    with pytest.raises(RuntimeError, match="No active object"):
        bpy.ops.dimred.mark_remove()
    with pytest.raises(RuntimeError, match="Select the meshes"):
        bpy.ops.dimred.mark_surface()

    empty = bpy.data.objects.new("Marker", None)
    bpy.context.scene.collection.objects.link(empty)
    _activate(empty)
    with pytest.raises(RuntimeError, match="not a mesh but Empty"):
        bpy.ops.dimred.mark_remove()

    with pytest.raises(RuntimeError, match="no World"):
        bpy.ops.dimred.remove()
    bpy.context.scene.world = bpy.data.worlds.new("World")
    with pytest.raises(RuntimeError, match="Mark the object to remove"):
        bpy.ops.dimred.remove()
    with pytest.raises(RuntimeError, match="shows no removal"):
        bpy.ops.dimred.clear()
    with pytest.raises(RuntimeError, match="Run Remove first"):
        bpy.ops.dimred.save_hdri(filepath="/nonexistent/never-written.exr")


def test_probe_centre_from_cursor_or_active_empty(registered):
    scene = bpy.context.scene
    scene.cursor.location = (1.0, 2.0, 3.0)
    _activate(_mesh("Floor"))
    bpy.ops.dimred.set_probe_center()
    assert tuple(scene.dimred.probe_center) == (1.0, 2.0, 3.0) and scene.dimred.use_probe_center

    empty = bpy.data.objects.new("ProbeCenter", None)
    empty.location = (0.0, 0.5, 1.25)
    scene.collection.objects.link(empty)
    bpy.context.view_layer.update()
    _activate(empty)
    bpy.ops.dimred.set_probe_center()
    assert tuple(scene.dimred.probe_center) == (0.0, 0.5, 1.25)


def test_mark_remove_and_toggle_surfaces(registered):
    settings = bpy.context.scene.dimred
    floor, wall, box = _mesh("Floor"), _mesh("Wall"), _mesh("Box")

    _activate(floor)
    wall.select_set(True)
    bpy.ops.dimred.mark_surface()
    assert settings.surface_names() == ("Floor", "Wall")

    _activate(box)
    bpy.ops.dimred.mark_remove()
    assert settings.target == box

    _activate(wall)
    box.select_set(True)
    bpy.ops.dimred.mark_surface()
    assert settings.surface_names() == ("Floor",)

    # Marking a surface as the object to remove takes it off the surfaces.
    _activate(floor)
    bpy.ops.dimred.mark_remove()
    assert settings.target == floor and settings.surface_names() == ()


def test_remove_refuses_a_relative_folder_in_an_unsaved_file(registered):
    scene = bpy.context.scene
    scene.world = bpy.data.worlds.new("World")
    box = _mesh("Box")
    _activate(box)
    bpy.ops.dimred.mark_remove()
    assert bpy.data.filepath == ""

    with pytest.raises(RuntimeError, match="not saved yet"):
        bpy.ops.dimred.remove()
    assert scene.dimred.last_report == ""


class _CheckingLayout:
    """Stands in for UILayout (which needs a window): checks what a panel's draw asks for."""

    icons = {item.identifier for item in bpy.types.UILayout.bl_rna.functions["label"].parameters["icon"].enum_items}

    def __init__(self, drawn: list[str]) -> None:
        self.drawn = drawn

    def __getattr__(self, name: str):
        def sub_layout(*args, **kwargs):
            return _CheckingLayout(self.drawn)

        return sub_layout

    def _icon(self, kwargs: dict) -> None:
        assert kwargs.get("icon", "NONE") in self.icons, kwargs["icon"]

    def prop(self, data, name: str, **kwargs) -> None:
        assert name in data.bl_rna.properties, name
        self._icon(kwargs)
        self.drawn.append(f"prop {name}")

    def operator(self, idname: str, **kwargs) -> _OperatorProperties:
        category, name = idname.split(".")
        assert hasattr(getattr(bpy.ops, category), name) and _operator_exists(name), idname
        self._icon(kwargs)
        self.drawn.append(f"operator {idname}")
        return _OperatorProperties(getattr(getattr(bpy.ops, category), name).get_rna_type())

    def label(self, **kwargs) -> None:
        self._icon(kwargs)
        self.drawn.append(f"label {kwargs.get('text', '')}")

    def progress(self, factor: float, type: str, text: str) -> None:
        assert 0.0 <= factor <= 1.0 and type in {'BAR', 'RING'}
        self.drawn.append(f"progress {text}")


class _OperatorProperties:
    """Stands in for the properties a layout's operator button returns: only existing ones can be set."""

    def __init__(self, rna) -> None:
        object.__setattr__(self, "_rna", rna)

    def __setattr__(self, name: str, value) -> None:
        assert name in self._rna.properties, name


def _draw(panel_class: type, context) -> list[str]:
    drawn: list[str] = []
    panel = type("PanelStandIn", (), {"layout": _CheckingLayout(drawn)})()
    panel_class.draw(panel, context)
    return drawn


def test_panels_draw_existing_properties_operators_and_icons(registered, monkeypatch):
    from diminished_reality.panels import sidebar

    scene = bpy.context.scene
    scene.dimred.surfaces.add().object = _mesh("Floor")
    for name, kind in (("Chair", 'REMOVE'), ("Box", 'RELOCATE')):
        entry = scene.dimred.removals.add()
        entry.object_name, entry.kind, entry.yaw, entry.distance_scale = name, kind, -40.0, 1.3
    drawn = _draw(sidebar.DIMRED_PT_main, bpy.context)
    assert {f"operator dimred.{name}" for name in OPERATORS if name != "cancel"} <= set(drawn)
    assert "label Floor" in drawn and "operator dimred.cancel" not in drawn
    assert {"prop yaw", "prop distance_scale", "label Chair", "label Box: yaw -40.0°, distance ×1.30"} <= set(drawn)

    # While a removal runs, its progress bar and Cancel replace the Remove button.
    running = type("Running", (), {"stage": "first_order", "fraction": 0.375})()
    monkeypatch.setattr(sidebar.session, "active", lambda: running)
    drawn = _draw(sidebar.DIMRED_PT_main, bpy.context)
    assert "progress First order 38 %" in drawn and "operator dimred.cancel" in drawn
    assert "operator dimred.remove" not in drawn
    monkeypatch.undo()

    assert not sidebar.DIMRED_PT_last_run.poll(bpy.context)
    scene.dimred.last_report = (
        '{"seconds": {"shadows": 1.5, "total": 2.0}, "skipped": [{"stage": "synthesis", "reason": "not yet"}],'
        ' "warnings": ["hidden region not filled"], "guards": {"reflectance_clamped_patches": 3},'
        ' "relocation": {"yaw": 40.0, "distance_scale": 1.3, "elevation_change": 7.3}}'
    )
    assert sidebar.DIMRED_PT_last_run.poll(bpy.context)
    assert "prop override_parameters" in _draw(sidebar.DIMRED_PT_parameters, bpy.context)
    drawn = _draw(sidebar.DIMRED_PT_last_run, bpy.context)
    for line in ("label total: 2.00 s", "label Skipped synthesis: not yet", "label hidden region not filled",
                 "label reflectance_clamped_patches: 3",
                 "label Moved: yaw 40.0°, distance ×1.30, view elevation +7.3°"):
        assert line in drawn
