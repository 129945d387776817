"""Quality presets: the parameters that trade accuracy for run time, by name.

The one place that names the presets, describes them and sets every parameter's default: the
command line's help and choices and the add-on's settings read them from here. This module
imports nothing beyond the standard library and the error type, so the add-on can read it when
it registers without loading the engine.

Sizes are relative (to the scene and to the removed object) so a preset means the same on a
doll's house and on a hall.
"""
from __future__ import annotations

from dataclasses import dataclass, replace

from .errors import DimredError


@dataclass(frozen=True)
class Params:
    """Every user-visible knob of a removal (the method's parameters: docs/design.md, "Parameters")."""

    patches: int = 500  # target number of radiosity patches on the room (coarse solution)
    object_patches: int = 100  # target number of patches on the removed object (a detailed one is clustered)
    sender_fraction: float = 0.98  # important senders hold this share of the bright patches' power
    max_senders: int = 32  # ... but at most this many (thesis default: 32)
    sender_samples: int = 4  # k: an important sender is sampled at k*k points for visibility
    fine_cells: float = 3.0  # fine grid: cells per object radius, near the object ...
    fine_pixels: float = 5.0  # ... and at most this many panorama pixels wide at the object's distance
    reach: float = 0.1  # the object's neighbourhood (fine lattice): where its solid angle exceeds this
    significance: float = 0.01  # shadow of a light computed per pixel where it can change E by this share
    # ... computed at the corners of cells at most this many working pixels wide (an eighth of
    # the object's radius at most) and mixed inside where that is right to within that share
    # (1: computed at every pixel)
    shadow_cell: int = 4
    bright_factor: float = 4.0  # important senders are this many times brighter than the median patch
    patch_samples: int = 2  # k*k points average the first-order change over patches near the object
    # a group of a detailed object's triangles sends its light as one point patch beyond this
    # many times its radius (`light.aggregate`): smaller is faster beside a 200k-triangle mesh
    aggregate_far: float = 6.0
    max_bounces: int = 8  # propagation of the change around the room
    bounce_tolerance: float = 2e-3  # stop when a bounce adds less than this share
    # plane raster cell, in panorama pixel footprints where the object was: finer keeps more detail, slower
    raster_cell: float = 0.7
    exemplar_margin: float = 1.5  # the raster spans the hole and this many times its extent around it
    synth_neighbourhood: int = 7  # synthesis window (odd): larger follows larger structures, slower
    synth_levels: int = 0  # pyramid levels of the synthesis, 0 = from the hole's size
    synth_generations: int = 2  # synthesis passes per level: more settle seams, slower
    # compose tiled and planked floors from shifted copies of the visible floor first, so that
    # their lines run on through the hole, and continue a band that crosses the hole between two
    # materials (a painted lane); False leaves all to the per-pixel synthesis
    synth_structure: bool = True
    seed: int = 0  # the synthesis's random seed: the same seed gives the same fill
    # where the removal brightens a surface (its shadow), weigh the photograph's detail down as
    # far as the surface's noise, measured on the panorama, grows in its dark pixels: a relit
    # contact shadow is otherwise speckled; False relights the noise with the light
    match_relit_noise: bool = True
    # the light is solved on a copy of the panorama at most this wide; the full-resolution
    # panorama takes it from there (upsampled, refined where it is sharp, filled at its own size)
    working_width: int = 1024  # even, at least MIN_WORKING_WIDTH
    refine_pixels: int = 200_000  # full-resolution pixels on sharp shadow edges given their own light, at most
    # the region to fill is segmented from the photograph in a band around the proxy's silhouette
    # this wide (a share of the object's angular size): wide enough for a proxy placed by eye a
    # few centimetres, degrees and percent off; 0 turns the segmentation off (the proxy decides)
    segmentation_band: float = 0.12
    # ... on the panorama's own pixels up to a window of this many, beyond it on a copy averaged
    # over 2 x 2 of them (4 x 4, ...): a close object at 8K is a window of half a million
    segmentation_pixels: int = 1 << 20
    # relocation: solver passes towards the inserted object's fixed point (2 at least: the first
    # lacks the object's reflected light)
    insertion_passes: int = 2


#: The narrowest working copy a run accepts: below it a room's objects are a few pixels wide.
MIN_WORKING_WIDTH = 128

#: The preset a run uses unless told otherwise (the command line's and the add-on's default).
DEFAULT_QUALITY = "balanced"

#: One line per preset, cheapest first: the command line's help and the add-on's quality menu.
DESCRIPTIONS = {
    "draft": "Fewest patches, light senders and bounces: fastest, with coarse shadows and relighting",
    "balanced": "The default trade-off between run time and accuracy",
    "final": "More visibility samples per light and a finer grid near the object: slower, most accurate",
}

PRESETS = {
    "draft": Params(patches=200, object_patches=40, sender_fraction=0.9, max_senders=12, sender_samples=2,
                    fine_cells=2.0, fine_pixels=8.0, reach=0.15, significance=0.03, patch_samples=1, aggregate_far=3.0,
                    max_bounces=4, bounce_tolerance=1e-2, refine_pixels=50_000, working_width=512,
                    segmentation_pixels=1 << 16),
    "balanced": Params(),
    # Balanced's patches, patch samples, neighbourhood and bounce tolerance: more of any of them
    # cost up to 3x and left the error against the ground-truth renders no lower on every scene
    # (more patches or patch samples raised it by up to 0.02); the sampled shadows and the finer
    # grid near the object lower it, at about twice balanced's time at 1024x512. Its cells stay
    # balanced's 5 pixels wide at most: 3 cost a fifth more time, moved the light error of 15
    # rendered rooms at 1024x512 by at most 0.003 either way and left 6 of them above balanced's
    # (by up to 0.002), where 5 left none.
    "final": Params(sender_fraction=0.995, max_senders=64, sender_samples=6, fine_cells=5.0,
                    significance=0.003, shadow_cell=2, max_bounces=16, insertion_passes=3, working_width=2048,
                    refine_pixels=800_000),
}


def params_for(quality: str, **overrides) -> Params:
    """The preset's parameters with any overrides (unknown names or presets are errors)."""
    if quality not in PRESETS:
        raise DimredError(f"unknown quality '{quality}': choose one of {', '.join(PRESETS)}")
    try:
        params = replace(PRESETS[quality], **overrides)
    except TypeError as exc:
        raise DimredError(f"unknown parameter: {exc}") from None
    problem = working_width_problem(params.working_width)
    if problem:
        raise DimredError(f"working_width {problem}, not {params.working_width!r}")
    return params


def working_width_problem(width: object) -> str | None:
    """What is wrong with `width` as a working width (the command line, the batch's jobs and the
    parameters say it alike), else None."""
    if isinstance(width, bool) or not isinstance(width, int) or width < MIN_WORKING_WIDTH or width % 2:
        return f"must be an even number of pixels, at least {MIN_WORKING_WIDTH}"
    return None


# The solver's accuracy knobs (not the synthesis's, not the relocation's passes).
_SOLVER_FIELDS = ("patches", "object_patches", "sender_fraction", "max_senders", "sender_samples", "fine_cells",
                  "fine_pixels", "reach", "significance", "shadow_cell", "patch_samples", "aggregate_far",
                  "max_bounces", "bounce_tolerance")


def rough(params: Params) -> Params:
    """`params` with the solver's accuracy of the draft preset: for a solve whose result only
    feeds a later, full one."""
    return replace(params, **{name: getattr(PRESETS["draft"], name) for name in _SOLVER_FIELDS})
