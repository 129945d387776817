"""Seconds and quality of hole filling: our synthesis (accelerated and exhaustive) and the 2D fills
people use today, on procedural floor textures with a square hole in the middle.

Prints a markdown table per case and a summary per method and hole size (both also written into
docs/results/bench_synthesis.md). Quality against the
known truth inside the hole: structure (correlation of the fill's band-pass luminance, box blur
of radius 1 minus box blur of radius 4, with the truth's: 1 = edges and lines where they really
run, 0 = out of phase or flat; `scenes.metrics.structure_correlation`), MAE (mean absolute
error; low only where the fill can be predicted, as for tile lines or a gradient, never for
noise), detail (high-pass std, result / truth: 1 is right, below is blur) and seam (mean
gradient magnitude on the 2 px either side of the hole's border, result / truth: above 1 is a
visible seam, below is a flattened border).

Ours is the add-on's fill: the hole composed from shifted copies where the texture repeats
(`addon.synthesis.structure`), the rest by the order-independent synthesis; "ours per-pixel" is
that synthesis alone (the fill before the structure-aware one), "ours exhaustive" its exact search.

The outside baselines are optional, benchmark-only dependencies (pins in
benchmarks/requirements-synthesis.txt; install them into a separate venv, e.g.
`python -m venv .venv-bench && .venv-bench/bin/pip install -r benchmarks/requirements-synthesis.txt`);
each one that does not import is listed as not installed. OpenCV, PatchMatch and Resynthesizer
work on 8-bit images, so their fills carry up to 1/510 of rounding. The exhaustive search is run
for holes up to --exhaustive-max pixels only (it takes minutes above).

Cases (--cases): `plain`, the texture as it is. `shadow`, the floor as the probe sees it: texture
times an irradiance E with a lamp's falloff and the object's soft shadow, half inside the hole
and half on the visible floor beside it (textures.lighting); the truth in the hole is texture
times E', the irradiance after the removal (no shadow). Ours fills as the add-on does: reflectance
image / E over the known pixels, synthesised, times E' in the hole; the 2D tools get the shaded
image and the same mask. `relit`: the same, but the 2D tools get the known pixels already relit
(texture times E', the shadow taken out around the hole as the removal does), so only the
lamp's falloff across the hole is left for them to get wrong. E and E' are exact here (in the
add-on they are estimates: the removal benchmark measures that). In every case the pixels
outside the hole are the truth's, so the seam measures the fill against its relit surroundings.
"""
from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[1]))
sys.path.insert(0, str(Path(__file__).resolve().parent))

from addon.synthesis.structure import fill_structured
from addon.synthesis.texture import SynthesisParams, fill
from results import Table, write
from scenes.metrics import structure_correlation
from textures import DEFAULT, TEXTURES, lighting

Method = Callable[[np.ndarray, np.ndarray], np.ndarray]  # (image, hole) -> filled image


def ours() -> Method:
    return lambda img, hole: fill_structured(img, ~hole, hole, SynthesisParams())[0]


def per_pixel(search: str) -> Method:
    return lambda img, hole: fill(img, ~hole, hole, SynthesisParams(search=search))


def _u8(img: np.ndarray) -> np.ndarray:
    return (np.clip(img, 0, 1) * 255 + 0.5).astype(np.uint8)


def telea() -> Method:
    import cv2

    return lambda img, hole: cv2.inpaint(_u8(img), hole.astype(np.uint8) * 255, 3, cv2.INPAINT_TELEA) / 255.0


def biharmonic() -> Method:
    from skimage.restoration import inpaint_biharmonic

    return lambda img, hole: inpaint_biharmonic(img, hole, channel_axis=-1)


def patchmatch() -> Method:
    import patchmatch as patchmatch_lib

    if not patchmatch_lib.patchmatch_available:
        raise ImportError("the PatchMatch native library did not load")

    def run(img, hole):
        patchmatch_lib.set_random_seed(0)
        # patch radius 3 (7 x 7 patches), as in its examples: its default 15 takes ~8 s per 128 px hole
        return patchmatch_lib.inpaint(_u8(img), hole.astype(np.uint8) * 255, patch_size=3) / 255.0

    return run


def resynthesizer() -> Method:
    import resynthesizer as resynthesizer_lib
    from PIL import Image

    def run(img, hole):
        params = resynthesizer_lib.getDefaultParams()
        params.isMakeSeamlesslyTileableHorizontally = params.isMakeSeamlesslyTileableVertically = 0  # heal
        mask = Image.fromarray(hole.astype(np.uint8) * 255)
        out = resynthesizer_lib.resynthesize(Image.fromarray(_u8(img)), mask, params)
        return np.asarray(out) / 255.0

    return run


def blur(img: np.ndarray, *, sigma: float = 2.0) -> np.ndarray:
    """Separable Gaussian blur of the first two axes, mirrored at the border."""
    r = int(3 * sigma)
    k = np.exp(-0.5 * (np.arange(-r, r + 1) / sigma) ** 2)
    k /= k.sum()
    for axis in (0, 1):
        p = np.moveaxis(np.pad(img, [(r, r) if a == axis else (0, 0) for a in range(img.ndim)], mode="reflect"),
                        axis, 0)
        img = np.moveaxis(sum(w * p[i:i + img.shape[axis]] for i, w in enumerate(k)), 0, axis)
    return img


def gradient_magnitude(img: np.ndarray) -> np.ndarray:
    gy, gx = np.zeros(img.shape[:2]), np.zeros(img.shape[:2])
    gy[1:-1] = np.linalg.norm(img[2:] - img[:-2], axis=-1) / 2
    gx[:, 1:-1] = np.linalg.norm(img[:, 2:] - img[:, :-2], axis=-1) / 2
    return np.hypot(gy, gx)


def border_ring(hole: np.ndarray, *, width: int = 2) -> np.ndarray:
    """Pixels within `width` of the hole's border, inside and outside."""
    p = np.pad(hole, width)
    shifts = [p[width + dy:width + dy + hole.shape[0], width + dx:width + dx + hole.shape[1]]
              for dy in range(-width, width + 1) for dx in range(-width, width + 1)]
    return np.any(shifts, axis=0) & ~np.all(shifts, axis=0)


def quality(out: np.ndarray, truth: np.ndarray, hole: np.ndarray) -> tuple[float, float, float, float]:
    structure = structure_correlation(out, truth, hole)
    mae = float(np.abs(out - truth)[hole].mean())
    detail = float((out - blur(out))[hole].std() / (truth - blur(truth))[hole].std())
    ring = border_ring(hole)
    seam = float(gradient_magnitude(out)[ring].mean() / gradient_magnitude(truth)[ring].mean())
    return structure, mae, detail, seam


def case_inputs(case: str, texture: np.ndarray, hole: np.ndarray
                ) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(truth, the image the fills get (0 in the hole), the irradiance that lights it, the irradiance
    after the removal) of one case."""
    ones = np.ones((*texture.shape[:2], 1), np.float32)
    if case == "plain":
        before = after = ones
    else:
        ys, xs = np.nonzero(hole)
        before, after = lighting(texture.shape[0], (ys.min(), ys.max() + 1, xs.min(), xs.max() + 1))
    lit = before if case == "shadow" else after
    return texture * after, np.where(hole[..., None], 0, texture * lit).astype(np.float32), lit, after


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--sizes", default="32,64,128,256", help="hole sides in pixels, comma separated")
    ap.add_argument("--textures", default=",".join(DEFAULT), help=f"comma separated, of {', '.join(TEXTURES)}")
    ap.add_argument("--image", type=int, default=512, help="side of the square test images")
    ap.add_argument("--exhaustive-max", type=int, default=64, help="largest hole the exhaustive search runs on")
    ap.add_argument("--quick", action="store_true", help="holes 64 and 128 only, no exhaustive search")
    ap.add_argument("--methods", default="", help="run only these methods, comma separated (default: all)")
    ap.add_argument("--cases", default="plain,shadow,relit", help="lighting cases, comma separated (see above)")
    ap.add_argument("--repeat", type=int, default=1,
                    help="runs per fill; the best time counts (the shared machine's load only ever adds time)")
    args = ap.parse_args()
    sizes = [64, 128] if args.quick else [int(s) for s in args.sizes.split(",")]
    exhaustive_max = 0 if args.quick else args.exhaustive_max

    methods: dict[str, Method | str] = {"ours": ours(), "ours per-pixel": per_pixel("accelerated"),
                                        "ours exhaustive": per_pixel("exhaustive")}
    for name, make in (("OpenCV Telea", telea), ("skimage biharmonic", biharmonic), ("PatchMatch", patchmatch),
                       ("Resynthesizer", resynthesizer)):
        try:
            methods[name] = make()
        except (ImportError, OSError) as e:
            methods[name] = f"not installed ({e.__class__.__name__})"
    if args.methods:
        methods = {name: methods[name] for name in args.methods.split(",")}

    table = Table(("case", "texture", "hole", "method", "s", "structure", "MAE", "detail", "seam"),
                  title=f"{args.image}x{args.image} images, square hole in the middle; "
                        f"default parameters {SynthesisParams()}")
    rows = []
    for case in args.cases.split(","):
        for texture in args.textures.split(","):
            floor = TEXTURES[texture](args.image)
            for size in sizes:
                hole = np.zeros(floor.shape[:2], bool)
                lo = (args.image - size) // 2
                hole[lo:lo + size, lo:lo + size] = True
                truth, seen, lit, after = case_inputs(case, floor, hole)  # the hole's truth is never seen
                for name, method in methods.items():
                    label = (case, texture, size, name)
                    if isinstance(method, str) or (name == "ours exhaustive" and size > exhaustive_max):
                        why = method if isinstance(method, str) else (
                            "skipped (--quick)" if args.quick else f"skipped (holes <= {exhaustive_max} px only)")
                        table.row(*label, why, "", "", "", "")
                        continue
                    seconds = np.inf
                    for _ in range(args.repeat):  # every method is deterministic: the runs differ in time only
                        t0 = time.perf_counter()
                        if name.startswith("ours"):  # reflectance: the shading divided out, E' multiplied in
                            reflectance = np.where(hole[..., None], 0, seen / lit).astype(np.float32)
                            out = method(reflectance, hole) * after
                        else:
                            out = method(seen, hole)
                        seconds = min(seconds, time.perf_counter() - t0)
                    structure, mae, detail, seam = quality(np.where(hole[..., None], out, truth), truth, hole)
                    rows.append((case, name, size, seconds, structure, mae, detail, seam))
                    table.row(*label, f"{seconds:.2f}", f"{structure:.2f}", f"{mae:.4f}", f"{detail:.2f}",
                              f"{seam:.2f}")

    means = Table(("case", "method", "hole", "s", "structure", "MAE", "detail", "seam"),
                  title="Mean over the textures:")
    for case in dict.fromkeys(r[0] for r in rows):
        for name in dict.fromkeys(r[1] for r in rows):
            for size in sizes:
                sel = np.array([r[3:] for r in rows if r[:3] == (case, name, size)])
                if len(sel):
                    s, structure, mae, detail, seam = sel.mean(axis=0)
                    means.row(case, name, size, f"{s:.2f}", f"{structure:.2f}", f"{mae:.4f}", f"{detail:.2f}",
                              f"{seam:.2f}")
    write(table, means)


if __name__ == "__main__":
    main()
