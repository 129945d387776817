"""A stand-in for Blender for the batch's tests: an executable that takes the command line a
job's child gets (`FAKE -b FILE -c dimred OP --object NAME --out DIR ...` and `FAKE -b -c
dimred inspect FILE...`) and behaves by the object's (or the file's) name, in milliseconds.

  Box      writes report.json and difference.exr (the .blend's bytes and the arguments), exit 0
  Missing  prints the command's one-line error for an unknown object, exit 2
  Crash    kills itself (SIGKILL)
  Slow     sleeps a minute
  Nap      sleeps half a second, then does what Box does
  Hog      holds 200 MB for 0.3 s, then does what Box does

Every call appends its arguments to the file FAKE_DIMRED_LOG names. In `inspect`, a file named
crash.blend kills the process and one named damaged.blend gets the reader's error.
"""
from __future__ import annotations

import json
import stat
import sys
from pathlib import Path

from addon.batch.execute import Launcher

FAKE = r'''
import json, os, signal, sys, time
args = sys.argv[1:]
log = os.environ.get("FAKE_DIMRED_LOG")
if log:
    with open(log, "a") as handle:
        handle.write(json.dumps(args) + "\n")
if args[:4] == ["-b", "-c", "dimred", "inspect"]:
    for blend in args[4:]:
        name = os.path.basename(blend)
        if name == "crash.blend":
            os.kill(os.getpid(), signal.SIGKILL)
        if name == "damaged.blend":
            print(json.dumps({"blend": blend, "error": f"cannot open {blend}: File format is not supported"}))
        else:
            print(json.dumps({"blend": blend, "size": [16, 8], "files": [blend + ".exr"]}), flush=True)
    sys.exit(0)
blend, op = args[1], args[4]
name = args[args.index("--object") + 1]
out = args[args.index("--out") + 1]
print("fake blender: read", blend)
if name == "Missing":
    print(f"dimred: error: no object named '{name}' in scene 'Scene'", file=sys.stderr)
    sys.exit(2)
if name == "Crash":
    os.kill(os.getpid(), signal.SIGKILL)
if name == "Slow":
    time.sleep(60)
if name == "Nap":
    time.sleep(0.5)
if name == "Hog":
    hog = bytearray(200_000_000)
    hog[::4096] = b"x" * len(hog[::4096])
    time.sleep(0.3)  # the batch reads the child's memory every 50 ms: a real job runs seconds
os.makedirs(out, exist_ok=True)
with open(os.path.join(out, "report.json"), "w") as handle:
    json.dump({"image_size": [16, 8], "seconds": {"total": 0.01}, "hidden_pixels": 5, "warnings": ["w"]}, handle)
with open(blend, "rb") as source, open(os.path.join(out, "difference.exr"), "wb") as target:
    # The arguments, less the staging folder's random name: the same job gives the same bytes.
    target.write(source.read() + json.dumps([a if a != out else "OUT" for a in args[4:]]).encode())
print(f"dimred: {op} '{name}'; wrote {out}")
'''


def fake_launcher(folder: Path) -> Launcher:
    """A Launcher whose 'Blender' is the stand-in, written into `folder`."""
    script = folder / "fake-blender"
    script.write_text(f"#!{sys.executable}\n{FAKE}", encoding="utf-8")
    script.chmod(script.stat().st_mode | stat.S_IXUSR)
    return Launcher(blender=str(script))


def calls(folder: Path) -> list[list[str]]:
    """The stand-in's calls so far (logged to folder/calls.jsonl by the `fake_blender` fixture)."""
    log = folder / "calls.jsonl"
    return [json.loads(line) for line in log.read_text().splitlines()] if log.exists() else []


def write_jobs(path: Path, jobs: list[dict | str]) -> Path:
    """A JSON Lines jobs file of `jobs` (a str is written as the line itself)."""
    path.write_text("".join((j if isinstance(j, str) else json.dumps(j)) + "\n" for j in jobs), encoding="utf-8")
    return path


def summary(out: Path) -> dict:
    return json.loads((out / "summary.json").read_text())
