"""Several removals composed into one edit of the panorama.

The rule, for the panel and the command line alike: each removal works on the panorama plus the
differences of the removals before it, with the objects removed before left out of the room's
geometry (they are no longer in the photograph, so they cast no shadow and reflect no light);
the edit is the panorama plus the sum of the differences. Removing an object again replaces its
own difference, which is why the panel keeps one per object.
"""
from __future__ import annotations

from collections.abc import Callable, Collection, Iterable, Sequence
from dataclasses import replace

import numpy as np

from .removal import RemovalResult
from .scene import SceneData


def without_objects(scene: SceneData, removed: Collection[str]) -> SceneData:
    """`scene` with the objects named in `removed` left out of the geometry: their triangles
    dropped, the other objects numbered on in their order (as the reader numbers them)."""
    gone = [i for i, name in enumerate(scene.object_names) if name in removed]
    if not gone:
        return scene
    kept = np.isin(scene.tri_object, gone, invert=True)
    renumbered = np.cumsum(np.isin(np.arange(len(scene.object_names)), gone, invert=True)) - 1
    return replace(scene, triangles=scene.triangles[kept],
                   tri_object=renumbered[scene.tri_object[kept]].astype(scene.tri_object.dtype),
                   object_names=[name for name in scene.object_names if name not in removed])


def on_earlier(scene: SceneData, differences: Iterable[np.ndarray], removed: Collection[str], *,
               own: bool = False) -> SceneData:
    """The scene a removal after earlier ones works on: its panorama (read) plus the earlier
    `differences` added in turn, and the `removed` objects left out of the geometry. The
    differences go into a float32 copy of the panorama, or with `own` (a panorama read for this
    run alone) into the panorama itself; an iterator may read each difference only when it is
    added, one at a time."""
    hdri = scene.hdri
    for difference in differences:
        if hdri is scene.hdri and not own:
            hdri = hdri.astype(np.float32)
        hdri += difference
        del difference  # before the iterator reads the next one
    return without_objects(replace(scene, hdri=hdri), removed)


def remove_in_order(scene: SceneData, names: Sequence[str],
                    remove: Callable[[SceneData, str], RemovalResult]) -> RemovalResult:
    """The objects `names` removed one after the other by `remove`, each from what the ones
    before left (`on_earlier`). The result's difference is the sum of theirs; with more than one
    object its report holds each removal's under "removals", their seconds summed per stage."""
    first, *rest = names
    result = remove(scene, first)
    if not rest:
        return result
    total, hidden = result.difference, result.hidden_mask.copy()
    reports = [result.report]
    for count, name in enumerate(rest, start=1):
        step = remove(on_earlier(scene, [total], names[:count]), name)
        total += step.difference
        hidden |= step.hidden_mask
        reports.append(step.report)
        del step
    return RemovalResult(difference=total, hidden_mask=hidden, report=_merged(names, reports), hdri=scene.hdri,
                         seen=result.seen)


def _merged(names: Sequence[str], reports: list[dict]) -> dict:
    seconds: dict[str, float] = {}
    for report in reports:
        for stage, value in report.get("seconds", {}).items():
            seconds[stage] = round(seconds.get(stage, 0.0) + value, 4)
    return {"objects": list(names), "removals": reports, "seconds": seconds,
            "image_size": reports[0].get("image_size"),
            "hidden_pixels": sum(r.get("hidden_pixels", 0) for r in reports),
            "hidden_region_filled": all(r.get("hidden_region_filled", True) for r in reports),
            "warnings": [f"{n}: {w}" for n, r in zip(names, reports, strict=True) for w in r.get("warnings", [])]}
