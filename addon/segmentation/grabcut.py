"""The object in a window of the panorama, GrabCut style, in a band around the proxy's silhouette.

The proxy is a guess a few per cent off; the photograph decides within `band` px of the proxy's
outline. Colour models of the object and of its local background (mixtures in log radiance) and
the graph cut they drive alternate a few times, each cut relabelling the band and each labelling
refitting the models; a matte then places the outline to a fraction of a pixel.

A wide band is first decided on the window halved (recursively, until the band is at most
_COARSE_BAND px): the fine level then only revisits a few pixels either side of that outline
and of the proxy's own (where a leg too thin for the coarse level may stand).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from .colour_model import ColourModel, fit_colour_model, log_features
from .cut import contrast_beta, contrast_graph, labelled, relax
from .masks import blur, boundary, dilate, double, erode, halve
from .matte import soft_alpha

_COARSE_BAND = 16  # widest band (px) decided at a level's own resolution
_REFINE = 3  # px either side of the coarse and the proxy's outline the finer level revisits
_SCORE_SAMPLES = 20000  # sure-object pixels the separation score averages over


@dataclass(frozen=True)
class ObjectSegmentation:
    """(h, w) arrays over the window."""

    object: np.ndarray  # bool: the pixel shows the object (alpha >= 0.5)
    alpha: np.ndarray  # float32 in [0, 1]: the object's share of the pixel (0 / 1 off the outline)
    band: np.ndarray  # bool: where the image decided (elsewhere the proxy did)
    # Mean edge strength along the segmented outline over the mean in the band: about 1 when the
    # outline follows no edge (the proxy lies over no object), several times that on one.
    outline_contrast: float
    # Mean log-likelihood ratio, object model over background model, of the sure-object pixels
    # (the proxy eroded by the band, and its parts too thin for that) that stayed object: about
    # 0 when the two models cannot tell the sides apart.
    separation: float


@dataclass(frozen=True)
class _Options:
    iterations: int
    smoothness: float
    components: int
    steps: int
    prior: float


@dataclass(frozen=True)
class _Level:
    """One resolution's labelling and what it was made from."""

    labels: np.ndarray  # (h, w) bool
    decided: np.ndarray  # (h, w) bool: the band
    sure: np.ndarray  # (h, w) bool: the proxy's core (eroded by the band) and its thin parts
    smooth: np.ndarray  # (h, w, 3) float32: the lightly denoised log image
    features: np.ndarray  # (h, w, 3) float32: the log image
    obj_model: ColourModel
    bg_model: ColourModel


def segment_object(image: np.ndarray, proxy: np.ndarray, *, band: int, iterations: int = 3,
                   smoothness: float = 4.0, components: int = 5, steps: int = 60, prior: float = 3.0,
                   seed: int = 0) -> ObjectSegmentation:
    """The object in `image` (h, w, 3) float32 linear radiance around `proxy` (h, w) bool.

    Pixels within `band` >= 1 px (Chebyshev) of the proxy's outline on either side are decided
    by the image, the others keep the proxy's label; the window must reach `band` + 2 px past the
    proxy. `iterations` rounds of colour models (`components` Gaussians each) and cut, the cut
    by `steps` primal-dual steps (half as many when warm-started); `smoothness` is the cost
    (nats) of a pixel of outline across a flat region, and `prior` what a pixel of the band must
    gain (nats) to leave the proxy's side, so that where the colours hardly tell the object from
    its surroundings (a grey box on a grey floor) the proxy stands. Deterministic for a given
    `seed`.
    """
    if band < 1:
        raise ValueError(f"band must be at least 1 px, got {band}")
    proxy = np.asarray(proxy, dtype=bool)
    if not proxy.any():
        raise ValueError("the proxy covers no pixel of the window")
    image = np.asarray(image, dtype=np.float32)
    rng = np.random.default_rng(seed)
    level = _label(image, proxy, band, rng,
                   _Options(iterations=iterations, smoothness=smoothness, components=components, steps=steps,
                            prior=prior))
    alpha = soft_alpha(image, level.labels, level.decided)
    obj = alpha >= 0.5
    kept = level.sure & obj
    sure = level.features[kept if kept.any() else level.sure]
    return ObjectSegmentation(object=obj, alpha=alpha, band=level.decided,
                              outline_contrast=_outline_contrast(level.smooth, obj, level.decided),
                              separation=_separation(sure, level.obj_model, level.bg_model, rng))


def _label(image: np.ndarray, proxy: np.ndarray, band: int, rng: np.random.Generator, options: _Options) -> _Level:
    features = log_features(image)
    smooth = blur(features)
    inner = erode(proxy, band)
    decided = dilate(proxy, band) & ~inner
    # The pixels the models start from: the proxy's core, with its parts too thin to have a
    # core (a stool's legs) taken whole, else they would have no colour in the object's model.
    sure = inner | (proxy & ~dilate(inner, band))
    local = dilate(proxy, 2 * band)
    if band > _COARSE_BAND:
        coarse = _label(halve(image), halve(proxy) >= 0.5, (band + 1) // 2, rng, options)
        labels = np.where(decided, double(coarse.labels, proxy.shape), proxy)
        free = decided & dilate(boundary(labels) | boundary(proxy), _REFINE)
        rounds = 1
        obj_pixels, bg_pixels = labels, local & ~labels
    else:
        labels = proxy.copy()
        free = decided
        rounds = options.iterations
        # The first models see the sure pixels only, either side of the band: the band may be a
        # quarter object on the proxy's outside or a quarter floor on its inside.
        obj_pixels, bg_pixels = sure, local & ~proxy & ~decided
    graph = contrast_graph(smooth, free, labels, smoothness=options.smoothness,
                           beta=contrast_beta(smooth, decided))
    free_features = features.reshape(-1, 3)[graph.free]
    towards_proxy = np.where(proxy.flat[graph.free], -options.prior, options.prior).astype(np.float32)
    state = labelled(graph, labels.flat[graph.free]) if band > _COARSE_BAND else None
    for _ in range(rounds):
        obj_model = fit_colour_model(features[obj_pixels], components=options.components,
                                     seed=int(rng.integers(1 << 31)))
        bg_model = fit_colour_model(features[bg_pixels], components=options.components,
                                    seed=int(rng.integers(1 << 31)))
        data = bg_model.log_likelihood(free_features) - obj_model.log_likelihood(free_features) + towards_proxy
        state = relax(graph, data, iterations=options.steps if state is None else options.steps // 2, start=state)
        labels.flat[graph.free] = state.labels
        obj_pixels, bg_pixels = (labels if labels.any() else sure), local & ~labels
    return _Level(labels=labels, decided=decided, sure=sure, smooth=smooth, features=features,
                  obj_model=obj_model, bg_model=bg_model)


def _outline_contrast(smooth: np.ndarray, obj: np.ndarray, decided: np.ndarray) -> float:
    """Mean edge strength on the outline over the band's. A mean, not a median: in a noiseless
    render most of the band is flat, its median strength 0 whatever the outline follows."""
    gy, gx = np.gradient(smooth, axis=(0, 1))
    strength = np.sqrt((gy * gy + gx * gx).sum(-1))
    edge = boundary(obj)
    typical = float(strength[decided].mean())
    if not edge.any() or typical <= 0.0:
        return 0.0
    return float(strength[edge].mean()) / typical


def _separation(sure: np.ndarray, obj_model: ColourModel, bg_model: ColourModel, rng: np.random.Generator) -> float:
    if len(sure) > _SCORE_SAMPLES:
        sure = sure[np.sort(rng.choice(len(sure), _SCORE_SAMPLES, replace=False))]
    return float(np.mean(obj_model.log_likelihood(sure) - bg_model.log_likelihood(sure)))
