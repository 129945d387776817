"""The Flamenco 3 job type (farm/flamenco/dimred_batch.js) compiled under node with a stand-in
for the Manager's `author` API: one task per .blend whose command is `blender -b FILE -c dimred
...` with arguments the command line's own parser accepts as meant."""
from __future__ import annotations

import json
import shutil
import subprocess
from pathlib import Path

import pytest

from addon.blender.cli import build_parser

ROOT = Path(__file__).resolve().parents[2]
JOB_TYPE = ROOT / "farm" / "flamenco" / "dimred_batch.js"
STANDIN = Path(__file__).with_name("flamenco_standin.js")
NODE = shutil.which("node")

pytestmark = pytest.mark.skipif(NODE is None, reason="node is not installed")


def _compile(**settings) -> dict:
    proc = subprocess.run([NODE, str(STANDIN), str(JOB_TYPE), json.dumps(settings)], capture_output=True, text=True,
                          timeout=60)
    assert proc.returncode == 0, proc.stderr
    return json.loads(proc.stdout)


def _command(task: dict) -> dict:
    [command] = task["commands"]
    assert command["type"] == "blender-render"
    return command["parameters"]


def test_the_job_type_declares_its_settings():
    job_type = _compile(blendfiles="/a.blend", objects="Box", output_root="/out")["jobType"]
    settings = {s["key"]: s for s in job_type["settings"]}
    assert job_type["label"] == "Diminished Reality batch"
    assert {key for key, s in settings.items() if s.get("required")} == {"blendfiles", "operation", "objects",
                                                                         "output_root"}
    assert settings["operation"]["choices"] == ["remove", "relocate", "align"]
    assert settings["quality"]["choices"] == ["draft", "balanced", "final"]
    assert settings["output_root"]["subtype"] == "dir_path"


def test_one_task_per_panorama_running_the_removal_command():
    compiled = _compile(blendfiles="/farm/rooms/kitchen.blend; /farm/rooms/hall.blend;/farm/other/kitchen.blend",
                        operation="remove", objects="Box; Chair", quality="final", planes="Floor",
                        align_first=True, output_root="/farm/out")
    tasks = compiled["tasks"]
    assert [t["name"] for t in tasks] == ["dimred-kitchen", "dimred-hall", "dimred-kitchen-2"]
    assert {t["type"] for t in tasks} == {"blender"}
    outs = []
    for task, blend in zip(tasks, ["/farm/rooms/kitchen.blend", "/farm/rooms/hall.blend", "/farm/other/kitchen.blend"],
                           strict=True):
        command = _command(task)
        assert (command["exe"], command["exeArgs"], command["argsBefore"], command["blendfile"]) == (
            "{blender}", "-b", [], blend)
        assert command["args"][:2] == ["-c", "dimred"]
        # What `blender -b FILE -c dimred ...` hands the command line.
        parsed = build_parser(blend_already_loaded=True).parse_args(command["args"][2:])
        assert parsed.command == "remove" and parsed.blend is None
        assert (parsed.objects, parsed.quality, parsed.plane, parsed.align) == (["Box", "Chair"], "final",
                                                                              ["Floor"], True)
        outs.append(parsed.out)
    assert outs == ["/farm/out/kitchen", "/farm/out/hall", "/farm/out/kitchen-2"]


def test_a_relocation_passes_its_move_and_windows_paths_keep_their_names():
    [task] = _compile(blendfiles="C:\\rooms\\Living Room.blend", operation="relocate", objects="Sofa", yaw=-35,
                      distance_scale=0.8, output_root="/out")["tasks"]
    command = _command(task)
    assert command["blendfile"] == "C:\\rooms\\Living Room.blend"
    parsed = build_parser(blend_already_loaded=True).parse_args(command["args"][2:])
    assert (parsed.command, parsed.objects, parsed.yaw, parsed.distance_scale, parsed.out, parsed.quality) == (
        "relocate", ["Sofa"], -35.0, 0.8, "/out/Living Room", "balanced")


@pytest.mark.parametrize("settings, message", [
    ({"blendfiles": " ; ", "objects": "Box"}, "no .blend file"),
    ({"blendfiles": "/a.blend", "objects": ""}, "no object"),
    ({"blendfiles": "/a.blend", "objects": "A;B", "operation": "align"}, "'align' takes one object, not 2"),
    ({"blendfiles": "/a.blend", "objects": "A", "operation": "explode"}, "unknown operation 'explode'"),
])
def test_a_job_the_command_cannot_run_is_refused_at_submission(settings, message):
    compiled = _compile(output_root="/out", **settings)
    assert "tasks" not in compiled and message in compiled["error"]
