"""The interactive Relocate tool's input without Blender: mouse, wheel, Shift, Ctrl, typed
values, Tab, confirm and cancel, and the header it shows."""
from __future__ import annotations

import ast
import importlib.util
import math
import sys
from dataclasses import dataclass
from pathlib import Path

import pytest

PATH = Path(__file__).resolve().parents[2] / "operators" / "support" / "relocate_input.py"
# Loaded as a file of its own: it must work without the operators package (which imports bpy).
_spec = importlib.util.spec_from_file_location("relocate_input_standalone", PATH)
ri = sys.modules[_spec.name] = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(ri)


@dataclass
class Event:
    type: str
    value: str = "PRESS"
    mouse_x: int = 0
    mouse_y: int = 0
    shift: bool = False
    ctrl: bool = False


def _move(tool, x, y, **modifiers) -> str:
    return tool.handle(Event("MOUSEMOVE", "NOTHING", x, y, **modifiers))


def _type(tool, keys: str) -> None:
    names = {".": "PERIOD", "-": "MINUS", "\b": "BACK_SPACE", "\t": "TAB"}
    words = ("ZERO", "ONE", "TWO", "THREE", "FOUR", "FIVE", "SIX", "SEVEN", "EIGHT", "NINE")
    for key in keys:
        assert tool.handle(Event(names.get(key) or words[int(key)])) == "UPDATE"


def test_the_module_does_not_import_blender():
    imported = {alias.name.split(".")[0] for node in ast.walk(ast.parse(PATH.read_text()))
                if isinstance(node, (ast.Import, ast.ImportFrom)) for alias in node.names}
    assert "bpy" not in imported and "mathutils" not in imported


def test_mouse_right_turns_clockwise_and_up_moves_away():
    tool = ri.RelocateInput(mouse=(100, 100))
    assert _move(tool, 140, 100) == "UPDATE"
    assert tool.yaw == pytest.approx(40 * ri.YAW_PER_PIXEL) and tool.yaw < 0
    assert tool.distance_scale == 1.0
    assert _move(tool, 140, 150) == "UPDATE"
    assert tool.distance_scale == pytest.approx(math.exp(50 * ri.LOG_SCALE_PER_PIXEL)) and tool.distance_scale > 1
    # The same position again changes nothing.
    assert _move(tool, 140, 150) == "NONE"


def test_the_first_move_without_a_start_position_only_records_it():
    tool = ri.RelocateInput()
    assert _move(tool, 500, 300) == "NONE"
    assert (tool.yaw, tool.distance_scale) == (0.0, 1.0)


def test_wheel_multiplies_the_distance_and_shift_makes_steps_finer():
    tool = ri.RelocateInput(mouse=(0, 0))
    tool.handle(Event("WHEELUPMOUSE"))
    tool.handle(Event("WHEELUPMOUSE"))
    assert tool.distance_scale == pytest.approx(ri.WHEEL_FACTOR ** 2)
    tool.handle(Event("WHEELDOWNMOUSE", shift=True))
    assert tool.distance_scale == pytest.approx(ri.WHEEL_FACTOR ** (2 - ri.FINE))
    _move(tool, 100, 0, shift=True)
    assert tool.yaw == pytest.approx(100 * ri.YAW_PER_PIXEL * ri.FINE)


def test_ctrl_snaps_while_held():
    tool = ri.RelocateInput.starting_at(0.0, 1.0, mouse=(0, 0))
    _move(tool, -29, 12)  # yaw 7.25 degrees, distance exp(0.048) = 1.049
    assert tool.yaw == pytest.approx(7.25)
    assert tool.handle(Event("LEFT_CTRL", ctrl=True)) == "UPDATE"
    assert tool.yaw == 5.0 and tool.distance_scale == pytest.approx(1.05)
    assert tool.handle(Event("LEFT_SHIFT", ctrl=True, shift=True)) == "UPDATE"
    assert tool.yaw == 7.0 and tool.distance_scale == pytest.approx(1.05)
    assert tool.handle(Event("LEFT_CTRL", "RELEASE")) == "UPDATE"
    assert tool.yaw == pytest.approx(7.25)


def test_snapping_never_reaches_a_zero_distance():
    tool = ri.RelocateInput.starting_at(0.0, 0.01)
    tool.handle(Event("LEFT_CTRL", ctrl=True))
    assert tool.distance_scale == ri.SNAP[1]


def test_typed_values_replace_the_mouse_per_field():
    tool = ri.RelocateInput.starting_at(10.0, 1.2, mouse=(0, 0))
    _type(tool, "40")
    assert tool.yaw == 40.0 and tool.distance_scale == pytest.approx(1.2)
    _move(tool, 50, 0)  # the mouse no longer moves a typed field
    assert tool.yaw == 40.0
    _type(tool, "-")
    assert tool.yaw == -40.0
    _type(tool, "-\b")
    assert tool.yaw == 4.0
    _type(tool, "\t1.3")
    assert (tool.yaw, tool.distance_scale) == (4.0, 1.3)
    _type(tool, ".5")  # a second point is ignored
    assert tool.distance_scale == 1.35
    _type(tool, "\b\b\b\b")  # erased: the mouse's value again
    assert tool.distance_scale == pytest.approx(1.2)


def test_a_partial_text_counts_as_zero():
    tool = ri.RelocateInput()
    _type(tool, "-")
    assert tool.yaw == 0.0 and not tool.error
    _type(tool, "\t.")
    assert tool.distance_scale == 0.0 and "greater than 0" in tool.error


def test_confirm_and_cancel_keys():
    for key in ("RET", "NUMPAD_ENTER", "SPACE", "LEFTMOUSE"):
        assert ri.RelocateInput().handle(Event(key)) == "CONFIRM"
        assert ri.RelocateInput().handle(Event(key, "RELEASE")) == "NONE"
    for key in ("ESC", "RIGHTMOUSE"):
        assert ri.RelocateInput().handle(Event(key)) == "CANCEL"


def test_an_invalid_distance_cannot_be_confirmed():
    tool = ri.RelocateInput()
    _type(tool, "\t-2")
    assert tool.distance_scale == -2.0
    assert tool.handle(Event("RET")) == "NONE"
    assert "greater than 0" in tool.header("Box", None)
    _type(tool, "-")
    assert tool.handle(Event("RET")) == "CONFIRM"


def test_navigation_passes_and_other_keys_are_taken():
    tool = ri.RelocateInput()
    assert tool.handle(Event("MIDDLEMOUSE")) == "PASS"
    assert tool.handle(Event("G")) == "NONE"
    assert tool.handle(Event("TIMER", "NOTHING")) == "NONE"
    assert (tool.yaw, tool.distance_scale) == (0.0, 1.0)


def test_header_shows_values_active_field_typed_text_and_keys():
    tool = ri.RelocateInput.starting_at(40.0, 1.3)
    assert tool.header("Box", -3.2).startswith(
        "Relocate 'Box': yaw [40.0°], distance ×1.30, view elevation \u22123.2° | "
        "Enter confirm · Esc cancel · Tab field")
    _type(tool, "\t-")
    assert "yaw 40.0°, distance [\u2212|]" in tool.header("Box", None)
    assert "view elevation" not in tool.header("Box", None)


def test_a_refused_place_cannot_be_confirmed_and_the_header_says_why():
    tool = ri.RelocateInput()
    tool.refusal = "at the new place 'Box' would cut through 'Wall'"
    assert tool.handle(Event("RET")) == "NONE"
    assert "would cut through 'Wall'" in tool.header("Box", 1.0)
    tool.refusal = ""
    assert tool.handle(Event("RET")) == "CONFIRM"
