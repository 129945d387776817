"""The object as the photograph shows it: the proxy's silhouette corrected by segmenting the
panorama around it, with the artist's mask applied.

A proxy placed by eye is a few centimetres, degrees and percent off. The region the removal
fills is therefore decided by the image in a band around the proxy's silhouette; the proxy
alone decides farther away. The window is segmented at the panorama's own resolution, or on
an area-averaged copy when it would exceed `max_pixels` (a close object in a 16K panorama).
"""
from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from ..errors import DimredError
from ..geometry import latlong
from ..geometry.mesh import Geometry
from ..geometry.planeraster import Frame
from ..geometry.raycast import Projection, trace_panorama
from ..geometry.span import pixel_span
from ..light.radiosity import LUMA
from ..quality import Params
from ..report import Report
from ..side_by_side import both
from .grabcut import ObjectSegmentation, segment_object
from .masks import blur, box_mean, dilate
from .user_mask import UserMask

_COARSE_WIDTH = 512  # the panorama's width at which the window is first found
_PAD = 2  # pixels the window reaches past the band
_MIN_BAND = 3
_SHADOW = 0.9  # an added pixel this much darker than the brightest background around it, ...
_SHADOW_CHROMA = 0.08  # ... its log chromaticity this close to the background's, is its shadow
_DARKEST = 0.3  # below the object, below this share of the background's median, ...
_LEG_CHROMA = 0.15  # ... its log chromaticity this far from the background's: the object's own
# A proxy whose silhouette and the segmented object share less than this is not over the object.
_MIN_OVERLAP = 0.25
_MIN_SEPARATION = 0.8  # below this the two sides' colours cannot be told apart ...
_MIN_CONTRAST = 2.6  # ... and below this the outline follows no edge of the image


@dataclass(frozen=True)
class SeenObject:
    """(h, w) maps over `frame`, a window of the panorama at the segmentation's resolution
    (`factor` panorama pixels to a side of each of its pixels)."""

    frame: Frame
    factor: int
    image: np.ndarray  # (h, w, 3) float32 radiance
    proxy: np.ndarray  # bool: the proxy is the first hit
    segmentation: ObjectSegmentation | None  # None where the image was not consulted
    shown: np.ndarray  # bool: what the removal fills (before its one-pixel margin)
    band: int  # half-width of the band the image decided, in pixels of `frame`

    def in_frame(self, frame: Frame, shape: tuple[int, int]) -> np.ndarray:
        """`shown` over an (h, w) window `frame` of the panorama at another resolution: a pixel
        of a coarser one is shown where any shown pixel falls into it, of a finer one where the
        shown pixel holding its centre is."""
        out = np.zeros(shape, dtype=bool)
        if frame.height < self.frame.height:
            r, c = np.nonzero(self.shown)
            scale = frame.height / self.frame.height
            rows = ((self.frame.row0 + r + 0.5) * scale).astype(np.int64)
            cols = ((np.mod(self.frame.col0 + c, self.frame.width) + 0.5) * scale).astype(np.int64)
            wr, wc, inside = frame.locate(rows, np.mod(cols, frame.width), shape)
            out[wr[inside], wc[inside]] = True
            return out
        scale = self.frame.height / frame.height
        rows = ((frame.row0 + np.arange(shape[0]) + 0.5) * scale).astype(np.int64)
        cols = ((np.mod(frame.col0 + np.arange(shape[1]), frame.width) + 0.5) * scale).astype(np.int64)
        rr, cc = np.broadcast_arrays(rows[:, None], cols[None, :])
        sr, sc, inside = self.frame.locate(rr, cc, self.shown.shape)
        out[inside] = self.shown[sr[inside], sc[inside]]
        return out

    def whole(self, height: int, width: int) -> np.ndarray:
        """(height, width) bool: `shown` over a whole panorama of that size."""
        return self.in_frame(Frame(0, 0, height, width), (height, width))

    def summary(self) -> dict[str, object]:
        """What the report says of it (pixel counts at the segmentation's resolution)."""
        proxy, shown = self.proxy, self.shown
        union = int((proxy | shown).sum())
        out: dict[str, object] = {
            "window": [int(self.shown.shape[1]), int(self.shown.shape[0])],
            "factor": self.factor,
            "band_pixels": self.band,
            "proxy_pixels": int(proxy.sum()),
            "filled_pixels": int(shown.sum()),
            "beyond_proxy": int((shown & ~proxy).sum()),
            "proxy_not_object": 0,
            "agreement": round(float((proxy & shown).sum() / union), 4) if union else 1.0,
        }
        seg = self.segmentation
        if seg is not None:
            out["proxy_not_object"] = int((proxy & ~seg.object).sum())
            out["segmented_pixels"] = int(seg.object.sum())
            out["outline_contrast"] = round(float(seg.outline_contrast), 3)
            out["separation"] = round(float(seg.separation), 3)
        return out


def seen_object(hdri: np.ndarray, geo: Geometry, index: int, *, segment: bool = True,
                band: float = Params.segmentation_band, max_pixels: int = Params.segmentation_pixels,
                mask: UserMask | None = None, rep: Report | None = None) -> SeenObject | None:
    """The object `index` of `geo` (probe frame) as the panorama `hdri` (H, W, 3) shows it; None
    when no pixel sees it (nor does the user's mask add any). `band` is the half-width of
    the band the image decides, as a share of the object's angular size. DimredError when the
    proxy does not lie over anything the photograph shows as an object there. A window larger
    than `max_pixels` is segmented on a copy averaged over 2 x 2 pixels (4 x 4, ...)."""
    height, width = hdri.shape[:2]
    on = geo.tri_object == index
    projection = geo.projection  # before the two threads below, so it is worked out once
    spot = _coarse_spot(geo.triangles[on], projection.take(on), mask, width, height)
    if spot is None:
        return None
    centre = geo.triangles[on].reshape(-1, 3)
    mid = 0.5 * (centre.min(axis=0) + centre.max(axis=0))
    radius = float(np.linalg.norm(centre - mid, axis=1).max())
    distance = float(np.linalg.norm(mid))
    angular = 2.0 * np.arcsin(min(1.0, radius / max(distance, 1e-12)))
    band_full = max(_MIN_BAND, int(np.ceil(band * angular * height / np.pi)))
    factor = _factor(spot, band_full, width, height, max_pixels)
    hs, ws = height // factor, width // factor
    band_px = max(_MIN_BAND, int(np.ceil(band_full / factor)))
    frame, shape = _window(spot, band_px + _PAD, hs, ws)
    window = (frame.row0, shape[0], frame.col0, shape[1])
    # The object and the rest are traced side by side (at 8K each is a window of 500k pixels).
    obj, others = both(
        lambda: trace_panorama(geo.triangles[on], ws, hs, window=window, projection=projection.take(on)),
        lambda: trace_panorama(geo.triangles[~on], ws, hs, window=window, projection=projection.take(~on)))
    proxy = (obj.tri >= 0) & ((others.tri < 0) | (obj.distance < others.distance))
    image = _window_image(hdri, frame, shape, factor)
    seg = None
    name = geo.object_names[index]
    if segment and proxy.any():
        if float(image.max()) <= 0.0:
            # A black panorama shows nothing to segment; its removal changes nothing either.
            if rep is not None:
                rep.warn(f"the panorama is black around '{name}': its proxy's silhouette is filled as modelled")
        elif float(np.ptp(image)) <= 1e-6 * float(image.max()):
            _refuse(name, 0.0)
        else:
            seg = segment_object(image, proxy, band=band_px)
            _check_overlap(seg, proxy, name)
            if _unclear(seg):
                # Nothing there stands apart from its surroundings: a proxy over bare floor, or
                # an object the photograph is too dark or noisy to show. Only a mask that paints
                # the object in says which.
                if mask is None or not mask.in_frame(frame, shape)[0].any():
                    _refuse_unclear(name)
                seg = None
                if rep is not None:
                    rep.warn(f"the photograph does not set '{name}' apart from its surroundings: its proxy's "
                             "silhouette and the mask are filled")
    shown = proxy | _added(image, proxy, seg, band_px) if seg is not None else proxy.copy()
    if seg is not None:
        shown |= _attached_dark(image, shown, band_px)
    if mask is not None:
        add, take = mask.in_frame(frame, shape)
        shown = (shown | add) & ~take
    seen = SeenObject(frame=frame, factor=factor, image=image, proxy=proxy, segmentation=seg, shown=shown,
                      band=band_px)
    if rep is not None:
        rep.info["segmentation"] = seen.summary()
    return seen


def _coarse_spot(tris: np.ndarray, projection: Projection, mask: UserMask | None, width: int, height: int
                 ) -> np.ndarray | None:
    """(hc, wc) bool: where the object (its raster and its vertices, so no sliver is missed)
    and the user's added pixels are at a coarse resolution; None when nowhere."""
    wc = min(width, _COARSE_WIDTH)
    hc = wc // 2
    spot = trace_panorama(tris, wc, hc, projection=projection).tri >= 0
    spot[latlong.uv_to_pixel(*latlong.direction_to_uv(tris.reshape(-1, 3)), wc, hc)] = True
    if mask is not None and mask.add.any():
        spot |= mask.in_frame(Frame(0, 0, hc, wc), (hc, wc))[0] | _scattered(mask.add, hc, wc)
    return spot if spot.any() else None


def _scattered(mask: np.ndarray, height: int, width: int) -> np.ndarray:
    """(height, width) bool: any pixel of a finer whole-panorama `mask` falls into it."""
    out = np.zeros((height, width), dtype=bool)
    r, c = np.nonzero(mask)
    out[(r * height) // mask.shape[0], (c * width) // mask.shape[1]] = True
    return out


def _factor(spot: np.ndarray, band: int, width: int, height: int, max_pixels: int) -> int:
    """Panorama pixels per segmentation pixel: 1 unless the window would be too large (then a
    power of two that divides the panorama's size)."""
    r0, r1, _, cols = pixel_span(spot, 1)
    scale = height / spot.shape[0]
    pixels = (r1 - r0) * scale + 2 * band
    pixels *= cols * scale + 2 * band
    factor = 1
    while pixels / factor**2 > max_pixels and width % (2 * factor) == 0 and height % (2 * factor) == 0:
        factor *= 2
    return factor


def _window(spot: np.ndarray, pad: int, height: int, width: int) -> tuple[Frame, tuple[int, int]]:
    """The window of a (height, width) panorama holding the coarse `spot` and `pad` pixels more."""
    r0, r1, c0, cols = pixel_span(spot, 1)
    scale = height / spot.shape[0]
    row0 = max(0, int(np.floor(r0 * scale)) - pad)
    row1 = min(height, int(np.ceil(r1 * scale)) + pad)
    ncols = int(np.ceil(cols * scale)) + 2 * pad
    if ncols >= width:
        return Frame(row0, 0, height, width), (row1 - row0, width)
    return Frame(row0, (int(np.floor(c0 * scale)) - pad) % width, height, width), (row1 - row0, ncols)


def _window_image(hdri: np.ndarray, frame: Frame, shape: tuple[int, int], factor: int) -> np.ndarray:
    """(h, w, 3) float32 radiance of the window, area-averaged over `factor` x `factor` pixels."""
    width = hdri.shape[1]
    cols = np.mod((frame.col0 * factor + np.arange(shape[1] * factor)), width)
    out = np.empty((*shape, 3), dtype=np.float32)
    band = max(1, (1 << 22) // (len(cols) * factor))
    for start in range(0, shape[0], band):
        stop = min(start + band, shape[0])
        rows = hdri[(frame.row0 + start) * factor:(frame.row0 + stop) * factor][:, cols]
        rows = np.maximum(rows.astype(np.float32), 0.0)
        out[start:stop] = rows.reshape(stop - start, factor, shape[1], factor, 3).mean(axis=(1, 3))
    return out


def _added(image: np.ndarray, proxy: np.ndarray, seg: ObjectSegmentation, band: int) -> np.ndarray:
    """The pixels the segmentation adds to the proxy's silhouette, less those a shadow on the
    background explains: darker by `_SHADOW` or more than the background around them (its mean
    log luminance within two bands), in the background's colour. The object's own contact
    shadow lies along its outline and looks like a dark face of it; left in, the fill would put
    lit floor where the photograph's shadow is."""
    added = seg.object & ~proxy
    if not added.any():
        return added
    # Smoothed twice: a render's or a sensor's noise would make every pixel's colour its own.
    y, chroma = _colour(blur(blur(np.maximum(image, 0.0))), image)
    log_y = np.log(y)
    around = ~seg.object & ~proxy & dilate(proxy, 2 * band)
    local, weight = box_mean(np.concatenate([log_y[..., None], chroma], axis=2), around, 2 * band)
    local_chroma = local[..., 1:]
    darker = log_y < local[..., 0] + np.log(_SHADOW)
    alike = np.abs(chroma - local_chroma).max(axis=2) < _SHADOW_CHROMA
    return added & ~(darker & alike & (weight > 0))


def _colour(smoothed: np.ndarray, image: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Luminance (h, w) and log chromaticity (h, w, 2: red and blue against green) of a smoothed
    copy of `image`, lifted by a millionth of the image's mean so that black has a colour."""
    rgb = smoothed.astype(np.float64) + 1e-6 * max(float(image.mean()), 1e-30)
    return rgb @ LUMA, np.log(rgb[..., [0, 2]] / rgb[..., 1:2])


def _attached_dark(image: np.ndarray, shown: np.ndarray, band: int) -> np.ndarray:
    """The pixels within `band` below the middle of the `shown` object, joined to it through such
    pixels, that are darker than `_DARKEST` of the background around them there (its median
    luminance within two bands) and clearly not in its colour: a leg of dark wood, the dark
    pixels where it touches the floor. A colour model of the object's body leaves them to the
    background; left, a box proxy's fill keeps a chair's legs standing in the room. A shadow
    keeps the floor's colour and is relit instead (its texture is the photograph's), and what
    is beside the object's upper half (a dark curtain, a desk's side) is not its legs."""
    rows = np.nonzero(shown)[0]
    if not len(rows):
        return np.zeros_like(shown)
    lower = (np.arange(shown.shape[0]) > np.median(rows))[:, None]
    # Smoothed once: a leg may be a few pixels wide.
    y, chroma = _colour(blur(np.maximum(image, 0.0)), image)
    around = ~shown & dilate(shown, 2 * band) & lower
    if not around.any():
        return np.zeros_like(shown)
    background = np.median(chroma[around], axis=0)
    dark = (around & (y < _DARKEST * float(np.median(y[around])))
            & (np.abs(chroma - background).max(axis=2) >= _LEG_CHROMA))
    reach = dark & dilate(shown, band)
    grown = np.zeros_like(shown)
    for _ in range(band):
        # two pixels at a time: smoothing brightens the pixels where a leg meets a bright body
        step = reach & dilate(shown | grown, 2) & ~grown
        if not step.any():
            break
        grown |= step
    # with the pixels its edge shares with the floor
    return dilate(grown, 1) & around


def _check_overlap(seg: ObjectSegmentation, proxy: np.ndarray, name: str) -> None:
    shared = float((seg.object & proxy).sum()) / max(1, int(proxy.sum()))
    if shared < _MIN_OVERLAP:
        _refuse(name, shared)


def _unclear(seg: ObjectSegmentation) -> bool:
    return seg.separation < _MIN_SEPARATION and seg.outline_contrast < _MIN_CONTRAST


_CHECK = "check that the right object is marked and that it stands where the panorama shows it"


def _refuse(name: str, shared: float) -> None:
    raise DimredError(
        f"the proxy '{name}' does not lie over what the photograph shows there ({shared:.0%} of its silhouette "
        f"looks like an object): {_CHECK}")


def _refuse_unclear(name: str) -> None:
    raise DimredError(
        f"the proxy '{name}' does not lie over what the photograph shows there (nothing there stands apart from "
        f"its surroundings, by colour or by an edge along its outline): {_CHECK}; if it does and the photograph is "
        "too dark or noisy to show it, paint a mask over it")
