"""Rough proxies: a scene's proxy moved off the object the panorama shows, and removals with it.

Users model proxies by eye, so the proxy in a .blend is a little off the object in the
photograph. A ground-truth pair is rendered with the exact object; `perturbed_blend` writes a
copy of its scene.blend with the proxy off by a `ProxyError` (the rendered pixels never change,
only the proxy), and `run_case` removes the object through the command line with that copy and
scores the edit against the pair's truth. `pose_error` says how far an alignment's correction
leaves the proxy from the exact pose.

A `ProxyError`'s `name` is also its spelling on a command line (`parse` reads it back):
"exact", "box" (the object's bounding box stands for it: a box modelled for an armchair),
"shift 2 cm x", "shift 5 cm at 45 deg", "turn -5 deg", "scale 0.95", "floor +1 cm", and
combinations joined by " + ".
"""
from __future__ import annotations

import json
import math
import re
import subprocess
import sys
import tempfile
import time
from collections.abc import Sequence
from dataclasses import asdict, dataclass
from pathlib import Path

import numpy as np

from . import metrics
from .images import read_exr

REPO = Path(__file__).resolve().parents[1]

# A component this much smaller than the other is float noise (cos 90 deg): the shift is named by its axis.
_AXIS_TOLERANCE = 1e-9


@dataclass(frozen=True)
class ProxyError:
    """How far the modelled proxy is off the real object (all about the exact pose).

    `shift`: metres in world x and y. `turn`: degrees counter-clockwise seen from above, about
    the vertical axis through the bounding box's centre. `scale`: uniform, about the bottom
    centre (the bounding box's centre in x and y, its lowest z). `floor`: metres the floor was
    modelled too high; the floor object and the proxy standing on it both move up by it.
    """

    shift: tuple[float, float] = (0.0, 0.0)
    turn: float = 0.0
    scale: float = 1.0
    floor: float = 0.0
    box: bool = False  # the proxy is the object's bounding box in its own frame ("a box for an armchair")

    @property
    def name(self) -> str:
        """Short label, e.g. "shift 5 cm at 45 deg + turn 3 deg"; "exact" when nothing is off."""
        parts = ["box"] if self.box else []
        x, y = self.shift
        if x or y:
            if abs(y) <= _AXIS_TOLERANCE * abs(x):
                parts.append(f"shift {_num(100.0 * x)} cm x")
            elif abs(x) <= _AXIS_TOLERANCE * abs(y):
                parts.append(f"shift {_num(100.0 * y)} cm y")
            else:
                parts.append(f"shift {_num(100.0 * math.hypot(x, y))} cm at {_num(math.degrees(math.atan2(y, x)))} deg")
        if self.turn:
            parts.append(f"turn {_num(self.turn)} deg")
        if self.scale != 1.0:
            parts.append(f"scale {_num(self.scale)}")
        if self.floor:
            parts.append(f"floor {'+' if self.floor > 0 else ''}{_num(100.0 * self.floor)} cm")
        return " + ".join(parts) or "exact"


def _num(value: float) -> str:
    return f"{round(value, 3) + 0.0:g}"


_NUMBER = r"([+-]?\d+(?:\.\d*)?)"
_PARTS = {
    "shift": re.compile(rf"shift {_NUMBER} cm (?:(x)|(y)|at {_NUMBER} deg)"),
    "turn": re.compile(rf"turn {_NUMBER} deg"),
    "scale": re.compile(rf"scale {_NUMBER}"),
    "floor": re.compile(rf"floor {_NUMBER} cm"),
}


def parse(label: str) -> ProxyError:
    """The `ProxyError` whose `name` is `label` (parts joined by " + ", in any order)."""
    fields: dict[str, object] = {}
    for part in label.strip().split(" + "):
        if part == "exact":
            continue
        if part == "box" and "box" not in fields:
            fields["box"] = True
            continue
        kind = part.split(" ", 1)[0]
        match = _PARTS[kind].fullmatch(part) if kind in _PARTS and kind not in fields else None
        if match is None:
            raise ValueError(f"cannot read {part!r} in {label!r}: expected 'exact' or parts such as 'box', "
                             "'shift 2 cm x', 'shift 5 cm y', 'shift 5 cm at 45 deg', 'turn -5 deg', 'scale 0.95', "
                             "'floor +1 cm'")
        value = float(match[1])
        if kind == "shift":
            metres, a = value / 100.0, math.radians(float(match[4] or 0.0))
            fields[kind] = ((metres, 0.0) if match[2] else (0.0, metres) if match[3]
                            else (metres * math.cos(a), metres * math.sin(a)))
        else:
            fields[kind] = value / 100.0 if kind == "floor" else value
    return ProxyError(**fields)


def error_matrix(error: ProxyError, bottom_centre: Sequence[float]) -> np.ndarray:
    """(4, 4) world matrix E that puts the exact object where the proxy is: the proxy's
    matrix_world = E @ the exact one. Scale and turn act about the bottom centre, whose vertical
    axis is the bounding box centre's; then the shift and the floor's rise move it."""
    b = np.asarray(bottom_centre, dtype=np.float64)
    a = math.radians(error.turn)
    linear = error.scale * np.array([[math.cos(a), -math.sin(a), 0.0], [math.sin(a), math.cos(a), 0.0],
                                     [0.0, 0.0, 1.0]])
    e = np.eye(4)
    e[:3, :3] = linear
    e[:3, 3] = b + np.array([error.shift[0], error.shift[1], error.floor]) - linear @ b
    return e


def pose_error(correction: np.ndarray | Sequence[Sequence[float]], error: ProxyError,
               bottom_centre: Sequence[float]) -> dict[str, float]:
    """What an alignment leaves of the proxy's error. `correction` is its (4, 4) world matrix C
    (the aligned proxy's matrix_world = C @ the proxy's), so the residual R = C @ E maps the
    exact object to the aligned one. `shift_cm`: how far R moves the bottom centre; `turn_deg`:
    R's turn about the vertical; `scale_percent`: R's uniform scale (cube root of the
    determinant) off 1. All 0 for a perfect alignment; C = identity gives the error itself."""
    r = np.asarray(correction, dtype=np.float64) @ error_matrix(error, bottom_centre)
    b = np.asarray(bottom_centre, dtype=np.float64)
    linear = r[:3, :3]
    # The rotation part of a turn times a uniform scale, read from the xy block's rotation.
    turn = math.atan2(linear[1, 0] - linear[0, 1], linear[0, 0] + linear[1, 1])
    return {
        "shift_cm": float(np.linalg.norm(linear @ b + r[:3, 3] - b) * 100.0),
        "turn_deg": abs(math.degrees(turn)),
        "scale_percent": abs(float(np.cbrt(np.linalg.det(linear))) - 1.0) * 100.0,
    }


@dataclass(frozen=True)
class PerturbedBlend:
    """A written copy of a scene with its proxy off by `error`: `path`, and the exact proxy's
    `bottom_centre` (3,) and `exact_matrix` (4, 4) as they were in the source .blend."""

    path: Path
    error: ProxyError
    bottom_centre: np.ndarray
    exact_matrix: np.ndarray


def perturbed_blend(blend: str | Path, object_name: str, error: ProxyError, out_blend: str | Path, *,
                    timeout: float | None = 300.0) -> PerturbedBlend:
    """Write `out_blend`: `blend` with object `object_name` moved by `error_matrix` (and, for
    `error.floor`, the object "Floor" raised by it; for `error.box`, its mesh first replaced by
    its bounding box in its own frame). Runs Blender in a subprocess
    (`scenes.perturb_job`) so that its state stays out of the caller; raises `RuntimeError`
    with the end of the job's output when it fails."""
    out_blend = Path(out_blend).resolve()
    with tempfile.TemporaryDirectory(prefix="perturb.") as tmp:
        result = Path(tmp) / "result.json"
        args = [str(Path(blend).resolve()), object_name, json.dumps(asdict(error)), str(out_blend), str(result)]
        proc = subprocess.run([sys.executable, "-m", "scenes.perturb_job", *args], cwd=REPO,
                              capture_output=True, text=True, timeout=timeout)
        if proc.returncode != 0:
            raise RuntimeError(f"perturbing {object_name!r} in {blend} failed (exit {proc.returncode}):\n"
                               f"{(proc.stdout + proc.stderr)[-3000:]}")
        done = json.loads(result.read_text())
    return PerturbedBlend(path=out_blend, error=error, bottom_centre=np.array(done["bottom_centre"]),
                          exact_matrix=np.array(done["exact_matrix"]))


@dataclass(frozen=True)
class CaseResult:
    """One removal with a rough proxy, scored against the truth rendered without the object.

    `total`: `hidden_region_scores`' object_shadow_ratio (error left over the object and region A,
    1 = nothing fixed); `lighting`: `lighting_error_ratio`; `ghost`: `ghost_share`; `far`:
    `far_damage`; `nans`: pixels of the edit with a NaN; `seconds`: the command's wall time;
    `pose`: `pose_error` of the report's alignment, None without one. A failed command leaves
    the scores NaN and its last line of output in `failure`.
    """

    error: ProxyError
    total: float
    lighting: float
    ghost: float
    far: float
    nans: int
    seconds: float
    pose: dict[str, float] | None
    failure: str | None


def run_case(pair: dict[str, Path], object_name: str, error: ProxyError, work: str | Path, *,
             quality: str = "balanced", cli_args: Sequence[str] = (), timeout: float | None = 900.0,
             proxy: PerturbedBlend | None = None) -> CaseResult:
    """Remove `object_name` through `python -m addon.cli remove` from the pair's scene with the
    proxy off by `error` (written into `work`, as is the command's output, unless `proxy` is
    that scene already written) and score it."""
    work = Path(work)
    work.mkdir(parents=True, exist_ok=True)
    if proxy is None:
        proxy = perturbed_blend(pair["blend"], object_name, error, work / "scene.blend")
    elif proxy.error != error:
        raise ValueError(f"the proxy given is off by {proxy.error}, not by {error}")
    out = work / "out"
    command = [sys.executable, "-m", "addon.cli", "remove", str(proxy.path), "--object", object_name,
               "--out", str(out), "--quality", quality, *cli_args]
    t0 = time.perf_counter()
    proc = subprocess.run(command, cwd=REPO, capture_output=True, text=True, timeout=timeout)
    seconds = time.perf_counter() - t0
    if proc.returncode != 0:
        last = (proc.stderr.strip() or proc.stdout.strip() or f"exit {proc.returncode}").splitlines()[-1]
        nan = float("nan")
        return CaseResult(error, nan, nan, nan, nan, 0, seconds, None, last)
    inp, edit, truth = read_exr(pair["input"]), read_exr(out / "edited.exr"), read_exr(pair["truth"])
    mask = np.load(pair["mask"])
    report = json.loads((out / "report.json").read_text())
    matrix = (report.get("alignment") or {}).get("matrix")
    return CaseResult(
        error=error,
        total=metrics.hidden_region_scores(inp, edit, truth, mask)["object_shadow_ratio"],
        lighting=metrics.lighting_error_ratio(inp, edit, truth, mask),
        ghost=metrics.ghost_share(edit, truth, mask),
        far=metrics.far_damage(inp, edit, truth, mask),
        nans=int(np.isnan(edit).any(axis=-1).sum()),
        seconds=seconds,
        pose=None if matrix is None else pose_error(matrix, error, proxy.bottom_centre),
        failure=None,
    )
