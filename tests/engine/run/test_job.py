"""A run as the operator starts it: the first preview before the panorama is read, the earlier
results composed from their files, and the caller's arrays left alone."""
from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from addon.callbacks import RunCallbacks
from addon.errors import DimredError
from addon.io.exr import read_exr, write_exr
from addon.run import job, small_copy
from tests.engine import tiny_room


@pytest.fixture
def request_on_file(tmp_path):
    """A removal of the box whose panorama is a file read in the run; the cache in tmp_path."""
    scene = tiny_room.scene_data(128, 64)
    write_exr(tmp_path / "pano.exr", scene.hdri)
    deferred = replace(scene, hdri=None, hdri_path=str(tmp_path / "pano.exr"))
    return job.RemovalRequest(scene=deferred, object_name="Box", quality="draft",
                              own_path=str(tmp_path / "own.exr"), layer_path=str(tmp_path / "layer.exr"),
                              cache_folder=str(tmp_path / "cache"))


def _run_logged(request, monkeypatch) -> list[str]:
    """Run `request`; the order of its panorama reads and previews."""
    events = []
    real = job.read_exr
    monkeypatch.setattr(job, "read_exr", lambda path: events.append(f"read {path}") or real(path))
    outcome = job.run(request, RunCallbacks(preview=lambda preview: events.append("preview")))
    outcome.staged.commit()
    return events


def test_the_first_preview_comes_before_the_panorama_is_read(request_on_file, monkeypatch):
    panorama = f"read {request_on_file.scene.hdri_path}"
    # The first run reads the file before it can preview, and keeps its small copy.
    events = _run_logged(request_on_file, monkeypatch)
    assert events[:2] == [panorama, "preview"]
    assert small_copy.cached(request_on_file.scene.hdri_path, request_on_file.cache_folder) is not None
    events = _run_logged(request_on_file, monkeypatch)
    assert events[:2] == ["preview", panorama] and events.count("preview") > 1


def test_earlier_results_are_read_from_their_files_and_composed(request_on_file, monkeypatch, tmp_path):
    _run_logged(request_on_file, monkeypatch)
    own = request_on_file.own_path
    again = replace(request_on_file, base=(own,), previous=own, own_path=str(tmp_path / "own2.exr"),
                    layer_path=str(tmp_path / "layer2.exr"))
    events = _run_logged(again, monkeypatch)
    # The earlier result's small copy was kept when it was written: the preview needs no read.
    assert events[0] == "preview"
    np.testing.assert_allclose(read_exr(again.layer_path), read_exr(own) + read_exr(again.own_path), atol=1e-6)


def test_the_callers_panorama_and_earlier_results_are_left_as_they_were(request_on_file):
    scene = tiny_room.scene_data(128, 64)
    base = np.full(scene.hdri.shape, 0.01, np.float32)
    kept = scene.hdri.copy(), base.copy()
    request = replace(request_on_file, scene=scene, base=(base,))
    job.run(request, RunCallbacks(preview=lambda preview: None)).staged.commit()
    np.testing.assert_array_equal(scene.hdri, kept[0])
    np.testing.assert_array_equal(base, kept[1])
    np.testing.assert_allclose(read_exr(request.layer_path), read_exr(request.own_path) + base, atol=1e-6)


def test_an_earlier_result_of_another_size_is_refused_and_nothing_is_written(request_on_file, tmp_path):
    write_exr(tmp_path / "small.exr", np.zeros((32, 64, 3), np.float32))
    request = replace(request_on_file, base=(str(tmp_path / "small.exr"),))
    with pytest.raises(DimredError, match="64x32 but the panorama is 128x64"):
        job.run(request, RunCallbacks(preview=lambda preview: None))
    assert sorted(p.name for p in tmp_path.iterdir()) == ["cache", "pano.exr", "small.exr"]
