"""The engine's front door: validate a SceneData, pick the preset, run the removal or relocation.

The command line, the Blender operators and the tests all call `remove_object` or
`relocate_object`.
"""
from __future__ import annotations

from collections.abc import Callable, Sequence
from dataclasses import replace

import numpy as np

from .alignment.fit import Alignment, align_object
from .callbacks import NO_CALLBACKS, RunCallbacks
from .errors import DimredError
from .quality import DEFAULT_QUALITY, Params, params_for
from .radiance import clamped_rows, negative_pixels, non_finite_pixels, round_to_stored_precision
from .relocation.fixedview import Move
from .relocation.insertion import relocate
from .removal import RemovalResult, remove
from .removal.sequence import photographed
from .removal.target import object_index
from .report import Report
from .run_memory import run_memory
from .scene import SceneData
from .segmentation.seen import SeenObject
from .segmentation.user_mask import UserMask


def validate(scene: SceneData) -> None:
    """DimredError for input the engine cannot work with (one line saying what)."""
    hdri = scene.hdri
    if hdri is None:
        raise DimredError("the panorama's pixels were not read (load the deferred file first)")
    if hdri.ndim != 3 or hdri.shape[2] != 3 or hdri.shape[0] < 2 or hdri.shape[1] < 4:
        raise DimredError(f"the world image must be an RGB panorama, got an array of shape {hdri.shape}")
    if hdri.shape[1] != 2 * hdri.shape[0]:
        raise DimredError(f"the world image is {hdri.shape[1]}x{hdri.shape[0]}: "
                          "a lat-long panorama is twice as wide as high")
    bad = non_finite_pixels(hdri)
    if bad:
        name = scene.hdri_path or "the world image"
        raise DimredError(f"{name} contains {bad} pixels with NaN or infinite values")
    if not np.isfinite(scene.center).all():
        raise DimredError("the probe centre is not a finite point")


def _run(scene: SceneData, quality: str, overrides: dict, compute: Callable[[SceneData, Params], RemovalResult],
         *, align: str | None = None, fit_height: bool = False) -> RemovalResult:
    validate(scene)
    params = params_for(quality, **overrides)
    # Negative radiance is not light: the engine reads it as black (`radiance.clamped_rows`),
    # and those pixels are passed through as they are. A panorama above the working width is
    # read in bands, clamped as it is read; a smaller one is read whole, so it gets a clamped copy.
    negative = negative_pixels(scene.hdri)
    original = scene.hdri
    if negative and scene.hdri.shape[1] <= params.working_width:
        scene = replace(scene, hdri=clamped_rows(scene.hdri, 0, scene.hdri.shape[0]))
    alignment = None
    # A script calling the pipeline gets the memory settings the command line and the add-on's
    # job give their runs (without them a 200k-triangle mesh's segmentation took 2-3x as long).
    with run_memory():
        if align is not None:
            alignment = align_object(scene, align, params=params, fit_height=fit_height)
            scene = alignment.moved(scene, object_index(scene, align))
        result = compute(scene, params)
        round_to_stored_precision(result.difference)
    report = dict(result.report)
    report["guards"] = {**report["guards"], "negative_input_pixels_clamped": negative}
    report["quality"] = quality
    report["parameters"] = {k: getattr(params, k) for k in params.__dataclass_fields__}
    report["image_size"] = [int(scene.hdri.shape[1]), int(scene.hdri.shape[0])]
    report["notes"] = [*report.get("notes", []), *scene.notes]
    if alignment is not None:
        report["alignment"] = alignment.summary()
        report["seconds"] = {**report["seconds"], "alignment": round(alignment.seconds, 4)}
        if not alignment.applied and not alignment.fits:
            report["warnings"] = [*report["warnings"], alignment.message]
    return replace(result, hdri=original, report=report)


def remove_object(
    scene: SceneData,
    object_name: str,
    *,
    planes: Sequence[str] = (),
    quality: str = DEFAULT_QUALITY,
    callbacks: RunCallbacks = NO_CALLBACKS,
    mask: UserMask | None = None,
    align: bool = False,
    fit_height: bool = False,
    **overrides: object,
) -> RemovalResult:
    """Remove `object_name` from the scene's panorama; `overrides` change single parameters of
    the quality preset. `callbacks.preview(difference)` gets coarse difference images before
    the result (see `removal.remove`). The region filled is where the photograph shows the
    object, `mask` added or taken away; with `align` the proxy's pose is first fitted to the
    photograph (`alignment.fit.align_object`; `report["alignment"]` says how)."""
    return _run(scene, quality, overrides,
                lambda s, params: remove(s, object_name, planes=list(planes), params=params, callbacks=callbacks,
                                         mask=mask),
                align=object_name if align else None, fit_height=fit_height)


def relocate_object(
    scene: SceneData,
    object_name: str,
    move: Move,
    *,
    planes: Sequence[str] = (),
    quality: str = DEFAULT_QUALITY,
    callbacks: RunCallbacks = NO_CALLBACKS,
    mask: UserMask | None = None,
    align: bool = False,
    fit_height: bool = False,
    **overrides: object,
) -> RemovalResult:
    """Move `object_name` under the fixed-view constraint (see `relocation.insertion.relocate`):
    the same images and report as a removal, with `report["relocation"]` describing the move;
    `mask` and `align` as for `remove_object` (the move starts from the aligned pose)."""
    return _run(scene, quality, overrides,
                lambda s, params: relocate(s, object_name, move, planes=list(planes), params=params,
                                           callbacks=callbacks, mask=mask),
                align=object_name if align else None, fit_height=fit_height)


def align_to_photo(scene: SceneData, object_name: str, *, quality: str = DEFAULT_QUALITY, fit_height: bool = False,
                   **overrides: object) -> Alignment:
    """Fit `object_name`'s pose on its support to its outline in the panorama (Align to Photo)."""
    validate(scene)
    # The fit reads the panorama only in the object's window, clamping negative radiance there
    # (`segmentation.seen`): no clamped copy of the whole panorama is made.
    return align_object(scene, object_name, params=params_for(quality, **overrides), fit_height=fit_height)


def photographed_object(scene: SceneData, object_name: str, *, quality: str = DEFAULT_QUALITY,
                        mask: UserMask | None = None, **overrides: object) -> SeenObject | None:
    """The object as the panorama shows it around its proxy (what a removal would fill)."""
    validate(scene)
    return photographed(scene, object_name, params_for(quality, **overrides), Report(), mask=mask)
