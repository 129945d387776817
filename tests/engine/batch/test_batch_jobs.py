"""The jobs file: every bad line reported with its number before anything runs, paths taken as
data relative to the file, the arguments each job's command gets, CSV as JSON Lines."""
from __future__ import annotations

import json
from pathlib import Path

import pytest

from addon.batch.jobs import JobsFileError, read_jobs
from addon.blender.cli import build_parser
from tests.engine.batch.standin import write_jobs


def _one(tmp_path: Path, scenes: Path, **fields) -> list:
    job = {"blend": str(scenes / "kitchen.blend"), "op": "remove", "object": "Box", **fields}
    return list(read_jobs(str(write_jobs(tmp_path / "jobs.jsonl", [job]))))


def test_a_good_file_gives_its_jobs_in_order_with_paths_relative_to_it(tmp_path, scenes):
    (scenes / "mask.png").write_bytes(b"png")
    path = write_jobs(scenes / "jobs.jsonl", [
        {"id": "k", "blend": "kitchen.blend", "op": "remove", "objects": ["Box", "Chair"],
         "params": {"quality": "final", "plane": ["Floor"], "mask": "mask.png", "align": True}},
        "",
        "# a comment line",
        {"blend": "bedroom.blend", "op": "relocate", "object": "Bed", "params": {"yaw": 40, "distance_scale": "1.3"}},
        {"blend": str(scenes / "hall.blend"), "op": "align", "object": "Bench", "params": {"save": True}},
    ])
    first, second, third = read_jobs(str(path))
    assert (first.line, first.id, first.blend, first.objects) == (1, "k", str(scenes / "kitchen.blend"),
                                                                   ("Box", "Chair"))
    assert first.parameters() == {"align": True, "mask": str(scenes / "mask.png"), "plane": ["Floor"],
                                  "quality": "final"}
    assert second.line == 4 and second.parameters() == {"distance_scale": 1.3, "yaw": 40.0}
    assert second.id.startswith("bedroom-relocate-Bed-") and third.line == 5
    # The default id does not depend on the line: reordering the file keeps every job's folder.
    reordered = write_jobs(scenes / "reordered.jsonl", [json.loads(line) for line in
                                                         reversed(path.read_text().splitlines())
                                                         if line.startswith("{")])
    assert {j.id for j in read_jobs(str(reordered))} == {first.id, second.id, third.id}


def test_every_bad_line_is_reported_with_its_number(tmp_path, scenes):
    blend = str(scenes / "kitchen.blend")
    path = write_jobs(tmp_path / "jobs.jsonl", [
        {"blend": blend, "op": "remove", "object": "Box"},
        {"blend": blend, "object": "Box"},
        {"blend": blend, "op": "explode", "object": "Box"},
        {"blend": str(tmp_path / "nowhere.blend"), "op": "remove", "object": "Box"},
        "{not json",
        {"blend": blend, "op": "remove"},
        {"blend": blend, "op": "relocate", "objects": ["A", "B"]},
        {"blend": blend, "op": "remove", "object": "Box", "params": {"yaw": 10}},
        {"blend": blend, "op": "remove", "object": "Box", "params": {"quality": "ultra"}},
        {"blend": blend, "op": "remove", "object": "Box", "params": {"mask": "no-mask.png"}},
        {"blend": blend, "op": "remove", "object": "Box", "params": {"colour": "red"}},
        {"blend": blend, "op": "remove", "object": "Box", "id": "../escape"},
        {"blend": blend, "op": "remove", "object": "Box", "id": "same"},
        {"blend": blend, "op": "remove", "object": "Chair", "id": "same"},
        {"blend": blend, "op": "relocate", "object": "Box", "params": {"yaw": "NaN"}},
        "[1, 2]",
        {"blend": blend, "op": "remove", "object": "Box", "params": {"working_width": 1000.5}},
        {"blend": blend, "op": "align", "object": "Box", "params": {"working_width": 2048}},
    ])
    with pytest.raises(JobsFileError) as caught:
        read_jobs(str(path))
    problems = caught.value.problems
    assert [int(p.split()[1].rstrip(":")) for p in problems] == [*range(2, 13), 14, 15, 16, 17, 18]
    expected = ["'op' must be one of", "'op' must be one of remove, relocate, align, not 'explode'",
                "no such .blend file", "not valid JSON", "missing field 'object'", "'relocate' takes one object",
                "parameter 'yaw' does not apply to 'remove'", "parameter 'quality' must be one of",
                "parameter 'mask' no such file", "unknown parameter 'colour'", "'id' must be",
                "id 'same' is already the id of line 13", "must be a finite number", "must be a JSON object",
                "parameter 'working_width' must be an even number of pixels, at least 128",
                "parameter 'working_width' does not apply to 'align'"]
    for problem, words in zip(problems, expected, strict=True):
        assert words in problem, problem


def test_an_empty_or_unreadable_file_is_refused(tmp_path):
    with pytest.raises(JobsFileError, match="holds no job"):
        read_jobs(str(write_jobs(tmp_path / "empty.jsonl", ["", "# nothing"])))
    with pytest.raises(Exception, match="cannot read the jobs file"):
        read_jobs(str(tmp_path / "absent.jsonl"))


def test_paths_and_names_are_data_never_expanded_or_evaluated(tmp_path, scenes, monkeypatch):
    monkeypatch.setenv("HOME", str(scenes))
    odd = scenes / "$HOME ~ `x` $(rm -rf).blend"
    odd.write_bytes(b"BLENDER odd")
    [job] = _one(tmp_path, scenes, blend=str(odd), object="$(touch pwned); Box")
    assert job.blend == str(odd)
    assert job.arguments("/out")[:3] == ["remove", "--object", "$(touch pwned); Box"]
    with pytest.raises(JobsFileError, match=r"no such \.blend file"):
        _one(tmp_path, scenes, blend="~/kitchen.blend")


@pytest.mark.parametrize("fields, tail", [
    ({}, []),
    ({"params": {"quality": "draft", "plane": ["Floor", "Rug"], "center": [0, 0.5, 1.6], "align": True,
                 "fit_height": True}},
     ["--align", "--center", "0.0", "0.5", "1.6", "--fit-height", "--plane", "Floor", "--plane", "Rug",
      "--quality", "draft"]),
    ({"op": "relocate", "params": {"yaw": -40, "distance_scale": 1.25, "working_width": "2048"}},
     ["--distance-scale", "1.25", "--working-width", "2048", "--yaw", "-40.0"]),
    ({"op": "align", "params": {"save": True}}, ["--save", "/out/aligned.blend"]),
    ({"op": "align", "params": {"save": False}}, []),
])
def test_the_arguments_are_what_the_command_line_takes(tmp_path, scenes, fields, tail):
    [job] = _one(tmp_path, scenes, **fields)
    arguments = job.arguments("/out")
    assert arguments == [job.op, "--object", "Box", "--out", "/out", *tail]
    # The command line's own parser accepts them as the job means them.
    parsed = build_parser(blend_already_loaded=True).parse_args(arguments)
    assert parsed.command == job.op and parsed.objects == ["Box"] and parsed.out == "/out"
    params = job.parameters()
    if "yaw" in params:
        assert (parsed.yaw, parsed.distance_scale) == (params["yaw"], params["distance_scale"])
        assert parsed.working_width == params["working_width"] == 2048
    if "plane" in params:
        assert parsed.plane == params["plane"] and parsed.center == params["center"]


def test_csv_with_a_header_reads_as_json_lines_do(tmp_path, scenes):
    path = scenes / "jobs.csv"
    path.write_text("id,blend,op,object,quality,yaw,distance_scale,plane\n"
                    "k,kitchen.blend,remove,Box;Chair,final,,,Floor;Rug\n"
                    ",bedroom.blend,relocate,Bed,,30,0.9,\n"
                    ",hall.blend,explode,Bench,,,,\n"
                    ",hall.blend,remove,Bench,,,,,extra\n", encoding="utf-8")
    with pytest.raises(JobsFileError) as caught:
        read_jobs(str(path))
    assert [p.split(":")[0] for p in caught.value.problems] == ["line 4", "line 5"]
    path.write_text("\n".join(path.read_text().splitlines()[:3]) + "\n", encoding="utf-8")
    first, second = read_jobs(str(path))
    assert first.objects == ("Box", "Chair") and first.parameters() == {"plane": ["Floor", "Rug"],
                                                                        "quality": "final"}
    assert second.line == 3 and second.parameters() == {"distance_scale": 0.9, "yaw": 30.0}
