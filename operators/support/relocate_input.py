"""The interactive Relocate tool's input, as a state machine without Blender (no bpy import).

It follows Blender's transform tools: the mouse drives the move (left/right: yaw about the
probe centre's vertical axis; up/down and the wheel: the distance factor, multiplicatively),
Shift makes the mouse ten times finer, holding Ctrl snaps (5 degrees and 0.05; 1 degree and
0.01 with Shift too), and typing digits enters a value (digits, '.', '-' toggles the sign,
Backspace, Tab to the other field) that replaces the mouse's for that field. Enter, Space or a
left click confirm; Esc or a right click cancel.

`handle` takes anything with the attributes of a `bpy.types.Event` it reads (type, value,
mouse_x, mouse_y, shift, ctrl), so the operator passes Blender's events as they are and the
tests pass plain objects. The values are absolute: yaw in degrees and the factor on the
object's distance as photographed, the same as the operator's properties.
"""
from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Protocol

YAW_PER_PIXEL = -0.25  # degrees; negative: the object follows the mouse as seen from the probe centre
LOG_SCALE_PER_PIXEL = 0.004  # 250 px up multiply the distance by e
WHEEL_FACTOR = 1.05
FINE = 0.1  # Shift: mouse and wheel steps times this
SNAP = (5.0, 0.05)  # Ctrl: yaw and distance factor snap to multiples of these
FINE_SNAP = (1.0, 0.01)  # Ctrl + Shift
FIELDS = ("yaw", "distance")

CONFIRM_KEYS = frozenset({"RET", "NUMPAD_ENTER", "SPACE", "LEFTMOUSE"})
CANCEL_KEYS = frozenset({"ESC", "RIGHTMOUSE"})
MODIFIER_KEYS = frozenset({"LEFT_SHIFT", "RIGHT_SHIFT", "LEFT_CTRL", "RIGHT_CTRL"})
# The viewport's own navigation keeps working while the tool runs, as in Blender's transforms.
NAVIGATION_KEYS = frozenset({"MIDDLEMOUSE", "TRACKPADPAN", "TRACKPADZOOM", "MOUSEROTATE", "NDOF_MOTION"})
DIGITS = {**{name: str(i) for i, name in enumerate(
    ("ZERO", "ONE", "TWO", "THREE", "FOUR", "FIVE", "SIX", "SEVEN", "EIGHT", "NINE"))},
    **{f"NUMPAD_{i}": str(i) for i in range(10)}, "PERIOD": ".", "NUMPAD_PERIOD": "."}
MINUS_KEYS = frozenset({"MINUS", "NUMPAD_MINUS"})

MINUS_SIGN = "\u2212"


class EventLike(Protocol):
    type: str
    value: str
    mouse_x: int
    mouse_y: int
    shift: bool
    ctrl: bool


@dataclass
class RelocateInput:
    """What the tool has been told so far; `handle` returns what the operator should do:
    'UPDATE' (the values changed), 'CONFIRM', 'CANCEL', 'PASS' (navigation, let the view have
    it) or 'NONE' (taken, nothing changed)."""

    yaw_mouse: float = 0.0  # degrees, unsnapped
    log_scale_mouse: float = 0.0  # natural logarithm of the distance factor, unsnapped
    mouse: tuple[int, int] | None = None  # the last mouse position, for relative steps
    active: int = 0  # the field that typing and Backspace act on: 0 yaw, 1 distance
    texts: list[str] = field(default_factory=lambda: ["", ""])
    snap: bool = False
    fine: bool = False
    refusal: str = ""  # why the place the values lead to breaks the constraint (the operator checks it)

    @classmethod
    def starting_at(cls, yaw: float, distance_scale: float, *, mouse: tuple[int, int] | None = None) -> RelocateInput:
        """A tool whose mouse values start at a move already set (the panel's fields)."""
        return cls(yaw_mouse=yaw, log_scale_mouse=math.log(distance_scale) if distance_scale > 0 else 0.0,
                   mouse=mouse)

    # -- the values -------------------------------------------------------------------------
    @property
    def yaw(self) -> float:
        typed = _typed_value(self.texts[0])
        if typed is not None:
            return typed
        return _snapped(self.yaw_mouse, self._step(0)) if self.snap else self.yaw_mouse

    @property
    def distance_scale(self) -> float:
        typed = _typed_value(self.texts[1])
        if typed is not None:
            return typed
        scale = math.exp(self.log_scale_mouse)
        if not self.snap:
            return scale
        step = self._step(1)
        return max(_snapped(scale, step), step)  # snapping never reaches 0, which is no placement

    @property
    def error(self) -> str:
        """Why the values cannot be confirmed, or ''."""
        if not math.isfinite(self.yaw):
            return "the yaw must be a finite angle"
        if not (math.isfinite(self.distance_scale) and self.distance_scale > 0.0):
            return "the distance factor must be greater than 0"
        return self.refusal

    def _step(self, index: int) -> float:
        return (FINE_SNAP if self.fine else SNAP)[index]

    # -- events -------------------------------------------------------------------------------
    def handle(self, event: EventLike) -> str:
        kind, value = event.type, event.value
        modifiers = (bool(event.ctrl), bool(event.shift))
        changed = modifiers != (self.snap, self.fine)
        self.snap, self.fine = modifiers
        if kind in NAVIGATION_KEYS:
            return "PASS"
        if kind == "MOUSEMOVE":
            return "UPDATE" if self._move(event.mouse_x, event.mouse_y) or changed else "NONE"
        if kind in ("WHEELUPMOUSE", "WHEELDOWNMOUSE"):
            step = math.log(WHEEL_FACTOR) * (FINE if self.fine else 1.0)
            self.log_scale_mouse += step if kind == "WHEELUPMOUSE" else -step
            return "UPDATE"
        if kind in MODIFIER_KEYS:
            return "UPDATE" if changed else "NONE"
        if value != "PRESS":
            return "NONE"
        if kind in CANCEL_KEYS:
            return "CANCEL"
        if kind in CONFIRM_KEYS:
            return "NONE" if self.error else "CONFIRM"
        if kind == "TAB":
            self.active = 1 - self.active
            return "UPDATE"
        if self._type(kind):
            return "UPDATE"
        return "UPDATE" if changed else "NONE"

    def _move(self, x: int, y: int) -> bool:
        last, self.mouse = self.mouse, (x, y)
        if last is None or last == (x, y):
            return False
        factor = FINE if self.fine else 1.0
        self.yaw_mouse += (x - last[0]) * YAW_PER_PIXEL * factor
        self.log_scale_mouse += (y - last[1]) * LOG_SCALE_PER_PIXEL * factor
        return True

    def _type(self, kind: str) -> bool:
        """Edit the active field's text; True when the key was one of the typing keys."""
        text = self.texts[self.active]
        if kind in DIGITS:
            char = DIGITS[kind]
            if char == "." and "." in text:
                return True
            text += char
        elif kind in MINUS_KEYS:
            text = text[1:] if text.startswith("-") else "-" + text
        elif kind == "BACK_SPACE":
            text = text[:-1]
        else:
            return False
        self.texts[self.active] = text
        return True

    # -- what the header shows ------------------------------------------------------------------
    def header(self, object_name: str, elevation_change: float | None) -> str:
        """The area header: the values (the active field in brackets, typed text with a
        cursor), the residual change of view elevation, the keys; and why Enter is refused."""
        shown = (f"{_number(self.yaw, '.1f')}°", f"×{_number(self.distance_scale, '.2f')}")
        parts = []
        for index, name in enumerate(FIELDS):
            text = self.texts[index]
            value = f"{text.replace('-', MINUS_SIGN)}|" if text else shown[index]
            parts.append(f"{name} [{value}]" if index == self.active else f"{name} {value}")
        line = f"Relocate '{object_name}': {', '.join(parts)}"
        if elevation_change is not None:
            line += f", view elevation {_number(elevation_change, '.1f')}°"
        if self.error:
            line += f" ({self.error})"
        return line + " | Enter confirm · Esc cancel · Tab field · Shift finer · Ctrl snap"


def _typed_value(text: str) -> float | None:
    """The typed text's number; None when nothing is typed. A text still being typed ('-', '.')
    counts as 0, as in Blender."""
    if not text:
        return None
    try:
        return float(text)
    except ValueError:
        return -0.0 if text.startswith("-") else 0.0


def _snapped(value: float, step: float) -> float:
    return round(value / step) * step


def _number(value: float, spec: str) -> str:
    return format(value, spec).replace("-", MINUS_SIGN)
