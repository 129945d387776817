"""Align to Photo: the pose of the marked object on its support that makes its silhouette from
the probe centre lie on the outline the photograph shows.

Points on the proxy's silhouette edges are matched to the nearest point of the segmented
outline and pulled along its normal (point-to-line ICP), the pose solved by damped Gauss-Newton
steps: a shift along the support, a turn about the vertical, a uniform scale about the bottom
centre, so the object keeps standing where it stands. From one viewpoint a silhouette cannot
tell a smaller object from a nearer one except through its support; `fit_height` therefore
fits the support's height instead of the scale, for a proxy whose size is known.
"""
from __future__ import annotations

import time
from dataclasses import dataclass, replace

import numpy as np

from ..errors import DimredError
from ..geometry import latlong
from ..geometry.mesh import to_probe_frame
from ..geometry.raycast import trace_panorama
from ..quality import Params
from ..removal.target import object_index, scene_geometry
from ..scene import SceneData
from ..segmentation.masks import dilate, erode
from ..segmentation.seen import SeenObject, seen_object
from .contour import Topology, silhouette_points, topology
from .outline import Outline, photographed_outline
from .pose import Pose, apply, bottom_centre
from .tangent import TangentPlane

_NAMES = ("shift x", "shift y", "height", "turn", "scale")
_SPACING = 0.5  # silhouette samples per pixel of outline
_FINEST = 1.5  # pixels: the robust scale the fit ends at ...
_SHRINK = 0.6  # ... shrinking by this factor a step
_MAX_STEPS = 40
_GAIN = 0.25  # the share of the modelled pose's robust cost a correction must save to be applied
# A centimetre of shift or height, a degree of turn, a percent of scale ...
_UNITS = np.array([0.01, 0.01, 0.01, np.radians(1.0), 0.01])
_UNSEEN = 0.02  # ... that moves the outline by less than this many pixels is left as modelled
_MIN_POINTS = 12
_OCCLUDED = 0.01  # a silhouette point farther than this share behind another surface is hidden by it
# Steps this small end the fit: a tenth of a millimetre, of a percent, of a hundredth degree.
_SMALL = np.array([1e-4, 1e-4, 1e-4, 1.7e-4, 1e-4])
# Corrections beyond these are not what a proxy placed by eye is off by: the fit found another
# object's outline, or none.
_MAX_SHIFT = 0.5  # of the object's size
_MAX_TURN = np.radians(20.0)
_MAX_SCALE = 1.25


@dataclass(frozen=True)
class Alignment:
    """The fitted correction of the object's pose and how well the outlines agree."""

    pose: Pose
    pivot: np.ndarray  # (3,) world bottom centre it turns and scales about
    applied: bool  # the fit converged to a plausible, clearly better pose (else the proxy stays where it was)
    fits: bool  # it converged, but no pose fits the outline clearly better than the modelled one
    iterations: int
    before_px: float  # median distance of the silhouette from the outline, pixels, before ...
    after_px: float  # ... and after
    points: int  # silhouette points that found the outline
    fitted: tuple[str, ...]
    message: str
    seconds: float

    @property
    def matrix(self) -> np.ndarray:
        """(4, 4) world matrix C: the corrected object's matrix_world is C @ its matrix_world."""
        return self.pose.matrix(self.pivot) if self.applied else np.eye(4)

    def moved(self, scene: SceneData, index: int) -> SceneData:
        """The scene with the object at the corrected pose (the scene itself when not applied)."""
        if not self.applied:
            return scene
        rows = np.asarray(scene.tri_object) == index
        tris = np.array(scene.triangles, dtype=np.float64)
        tris[rows] = apply(self.matrix, tris[rows])
        return replace(scene, triangles=tris)

    def summary(self) -> dict[str, object]:
        """What report.json says of it."""
        return {
            "applied": self.applied,
            "fits_as_modelled": self.fits,
            "message": self.message,
            "fitted": list(self.fitted),
            "shift_cm": [round(float(v) * 100.0, 3) for v in self.pose.shift],
            "turn_deg": round(float(np.degrees(self.pose.turn)), 4),
            "scale_percent": round((self.pose.scale - 1.0) * 100.0, 4),
            "pivot": [float(v) for v in self.pivot],
            "matrix": self.matrix.tolist(),
            "outline_median_px": {"before": round(self.before_px, 3), "after": round(self.after_px, 3)},
            "silhouette_points": self.points,
            "iterations": self.iterations,
            "seconds": round(self.seconds, 4),
        }


@dataclass(frozen=True)
class _Fit:
    """The silhouette at one pose against the outline."""

    points: np.ndarray  # (N, 3) probe frame, those that found the outline
    residual: np.ndarray  # (N,) along the outline's normal, tangent-plane units
    normals: np.ndarray  # (N, 2)
    weight: np.ndarray  # (N,) robust weight times the outline's trust there
    spread: np.ndarray  # residuals of every point within the band of the outline
    cost: float
    candidates: int


def align_object(scene: SceneData, object_name: str, *, params: Params, fit_height: bool = False) -> Alignment:
    """Fit the pose of `object_name` to its outline in the scene's panorama. DimredError when
    the object is not seen from the probe centre or its proxy lies over no object there; a fit
    that does not converge to a plausible pose is returned with `applied` False."""
    started = time.perf_counter()
    index = object_index(scene, object_name)
    if params.segmentation_band <= 0:
        raise DimredError("Align to Photo needs the segmentation: segmentation_band must be above 0")
    geo = scene_geometry(scene)
    if not (geo.tri_object == index).any():
        raise DimredError(f"'{object_name}' has no faces to align")
    # The preset's resolution, as the removal segments: a draft at 8K aligns to the outline its
    # removal will fill, found on 4 x 4 averages.
    seen = seen_object(scene.hdri, geo, index, band=params.segmentation_band, max_pixels=params.segmentation_pixels)
    if seen is None or not seen.proxy.any():
        raise DimredError(f"'{object_name}' is not visible from the probe centre: there is no outline to align to")
    if seen.segmentation is None:
        raise DimredError(f"the panorama is black around '{object_name}': there is no outline to align to")
    world = np.asarray(scene.triangles, dtype=np.float64)[np.asarray(scene.tri_object) == index]
    problem = _Problem.of(scene, seen, geo.triangles[geo.tri_object != index], world, fit_height)
    pose = Pose.identity()
    # The robust scale shrinks from the band's width to about a pixel: first every point near
    # the outline pulls, at the end only those on it (a shadow or a floor tile the segmentation
    # took in lies pixels away and stops counting).
    scale = problem.seen.band * problem.pixel
    fit = problem.fit(pose, scale)
    if len(fit.points) < _MIN_POINTS:
        raise DimredError(f"'{object_name}' shows too little outline in the panorama to align it "
                          f"({len(fit.points)} silhouette points found it)")
    before = problem.rms_px(fit)
    damping, steps, converged = 1e-3, 0, False
    while steps < _MAX_STEPS:
        steps += 1
        for _ in range(8):
            step = problem.step(fit, pose, damping)
            trial = pose.stepped(step)
            trial_fit = problem.fit(trial, scale)
            if trial_fit.cost <= fit.cost and len(trial_fit.points) >= _MIN_POINTS:
                pose, fit, damping = trial, trial_fit, max(damping / 3.0, 1e-7)
                break
            damping *= 10.0
        else:
            step = np.zeros(5)  # no step lowers the cost: a minimum at this scale
        finest = scale <= _FINEST * problem.pixel
        if finest and np.all(np.abs(step) <= _SMALL):
            converged = True
            break
        scale = max(_FINEST * problem.pixel, scale * _SHRINK)
        fit = problem.fit(pose, scale)
    unseen = problem.undetermined(fit, pose) if len(fit.points) else ()
    if unseen:
        keep = np.ones(5)
        keep[list(unseen)] = 0.0
        pose = Pose(pose.shift * keep[:3], pose.turn * keep[3], float(np.exp(np.log(pose.scale) * keep[4])))
        fit = problem.fit(pose, scale)
    after = problem.rms_px(fit)
    size = float(np.ptp(world.reshape(-1, 3), axis=0).max())
    plausible = (np.linalg.norm(pose.shift) <= _MAX_SHIFT * size and abs(pose.turn) <= _MAX_TURN
                 and 1.0 / _MAX_SCALE <= pose.scale <= _MAX_SCALE)
    # A correction the outline hardly prefers to the modelled pose is not one: where the image
    # barely tells the object from its background (a crate against a wall of its colour) the fit
    # wanders to what the segmentation got wrong.
    modelled = problem.fit(Pose.identity(), scale).cost
    better = fit.cost <= (1.0 - _GAIN) * modelled
    applied = converged and plausible and better
    fits = converged and plausible and not better
    if applied:
        message = (f"aligned '{object_name}': moved {np.linalg.norm(pose.shift) * 100:.1f} cm, turned "
                   f"{np.degrees(pose.turn):.2f} deg, scaled {(pose.scale - 1) * 100:+.2f} %; outline within "
                   f"{after:.2f} px (was {before:.2f})")
    elif fits:
        message = (f"'{object_name}' already fits its outline in the panorama as well as any pose the outline "
                   f"tells (within {before:.2f} px); the proxy is left as modelled")
    elif not converged:
        message = f"alignment of '{object_name}' did not converge in {steps} steps; the proxy is left where it was"
    else:
        message = (f"alignment of '{object_name}' found no plausible pose (it would move "
                   f"{np.linalg.norm(pose.shift) * 100:.0f} cm, turn {np.degrees(pose.turn):.0f} deg, scale "
                   f"{(pose.scale - 1) * 100:+.0f} %); the proxy is left where it was")
    if applied and unseen:
        message += f" ({', '.join(_NAMES[k] for k in unseen)}: not told by the outline, left as modelled)"
    return Alignment(pose=pose if applied else Pose.identity(), pivot=problem.pivot, applied=applied, fits=fits,
                     iterations=steps, before_px=before, after_px=after if applied else before,
                     points=len(fit.points), fitted=tuple(_NAMES[k] for k in problem.columns if k not in unseen),
                     message=message, seconds=time.perf_counter() - started)


@dataclass(frozen=True)
class _Problem:
    """What stays fixed while the pose is fitted."""

    seen: SeenObject
    outline: Outline
    plane: TangentPlane
    topo: Topology
    world: np.ndarray  # (T, 3, 3) the object's triangles as modelled
    pivot: np.ndarray
    center: np.ndarray
    rotation: np.ndarray
    others: np.ndarray  # (h, w) distance of the rest of the scene in the window (inf: nothing)
    columns: np.ndarray  # which of (dx, dy, dz, turn, log scale) are fitted
    pixel: float  # a pixel in tangent-plane units
    trust: np.ndarray  # (M,) weight of each outline point: its contrast against the outline's typical one

    @classmethod
    def of(cls, scene: SceneData, seen: SeenObject, others: np.ndarray, world: np.ndarray, fit_height: bool
           ) -> _Problem:
        f = seen.frame
        h, w = seen.shown.shape
        window = (f.row0, h, f.col0, w)
        rest = trace_panorama(others, f.width, f.height, window=window)
        probe = to_probe_frame(world.reshape(-1, 3), scene.center, scene.rotation)
        plane = TangentPlane.at(0.5 * (probe.min(axis=0) + probe.max(axis=0)))
        outline = photographed_outline(seen, plane)
        typical = float(np.median(outline.contrast)) if len(outline.contrast) else 1.0
        trust = np.clip(outline.contrast / max(typical, 1e-12), 0.0, 2.0)
        return cls(seen=seen, outline=outline, plane=plane, topo=topology(world), trust=trust,
                   world=world, pivot=bottom_centre(world), center=np.asarray(scene.center, dtype=np.float64),
                   rotation=np.asarray(scene.rotation, dtype=np.float64),
                   others=np.where(rest.tri >= 0, rest.distance, np.inf),
                   columns=np.array([0, 1, 2, 3] if fit_height else [0, 1, 3, 4]), pixel=np.pi / f.height)

    def fit(self, pose: Pose, scale: float) -> _Fit:
        """The silhouette of the object at `pose` matched to the outline, residuals weighed by
        the outline's contrast and a biweight of `scale` (tangent-plane units)."""
        matrix = pose.matrix(self.pivot)
        vertices = to_probe_frame(apply(matrix, self.topo.vertices), self.center, self.rotation)
        points = silhouette_points(vertices, self.topo, spacing=_SPACING * self.pixel)
        points = points[self._visible(points, to_probe_frame(apply(matrix, self.world), self.center, self.rotation))]
        if not len(points) or not len(self.outline.points):
            return _Fit(points[:0], np.zeros(0), np.zeros((0, 2)), np.zeros(0), np.zeros(0), np.inf, len(points))
        x = self.plane.project(points)
        nearest = _nearest(x, self.outline.points)
        offset = x - self.outline.points[nearest]
        normals = self.outline.normals[nearest]
        residual = np.einsum("ij,ij->i", offset, normals)
        near = np.linalg.norm(offset, axis=1) <= self.seen.band * self.pixel
        trust = self.trust[nearest]
        loss = trust * _biweight_loss(np.where(near, residual, np.inf), scale)
        keep = near & (np.abs(residual) < scale)
        weight = trust[keep] * (1.0 - (residual[keep] / scale) ** 2) ** 2
        return _Fit(points[keep], residual[keep], normals[keep], weight, residual[near], float(loss.mean()),
                    len(points))

    def _visible(self, points: np.ndarray, triangles: np.ndarray) -> np.ndarray:
        """Which silhouette points lie on the object's visible outline: on the boundary of its
        rasterised silhouette and not behind another surface."""
        f = self.seen.frame
        h, w = self.seen.shown.shape
        hits = trace_panorama(triangles, f.width, f.height, window=(f.row0, h, f.col0, w))
        shown = (hits.tri >= 0) & (hits.distance < self.others)
        strip = dilate(shown, 1) & ~erode(shown, 1)
        row, col = latlong.uv_to_pixel(*latlong.direction_to_uv(points), f.width, f.height)
        r, c, inside = f.locate(row, col, shown.shape)
        distance = np.linalg.norm(points, axis=1)
        return (inside & strip[r, c] & (self.others[r, c] >= distance * (1.0 - _OCCLUDED))
                & self.plane.in_front(points))

    def jacobian(self, fit: _Fit, pose: Pose) -> np.ndarray:
        """(N, 5) how the residuals change with a small pose step (dx, dy, dz, turn, log scale)."""
        world = (fit.points @ self.rotation) + self.center  # probe frame back to world (R orthonormal)
        arm = world - (self.pivot + pose.shift)
        unit = np.broadcast_to(np.eye(3), (len(arm), 3, 3))
        turn = np.cross(np.array([0.0, 0.0, 1.0]), arm)
        d_world = np.concatenate([unit, turn[:, :, None], arm[:, :, None]], axis=2)  # (N, 3, 5)
        d_probe = np.einsum("ij,njk->nik", self.rotation, d_world)
        along = np.einsum("nc,ncj->nj", fit.normals, self.plane.jacobian(fit.points))
        return np.einsum("nj,njk->nk", along, d_probe)

    def step(self, fit: _Fit, pose: Pose, damping: float) -> np.ndarray:
        """(5,) the damped Gauss-Newton step from `pose` (zero where not fitted)."""
        jac = self.jacobian(fit, pose)[:, self.columns]
        a = jac.T @ (jac * fit.weight[:, None])
        g = jac.T @ (fit.weight * fit.residual)
        diagonal = np.diag(a).copy()
        ridge = damping * diagonal + 1e-6 * max(float(diagonal.max()), 1e-300)
        out = np.zeros(5)
        out[self.columns] = -np.linalg.solve(a + np.diag(ridge), g)
        return out

    def undetermined(self, fit: _Fit, pose: Pose) -> tuple[int, ...]:
        """The fitted parameters the outline hardly constrains: a centimetre, degree or percent
        of them moves it by less than `_UNSEEN` px rms (a cylinder's turn, say)."""
        moved = np.sqrt((self.jacobian(fit, pose) ** 2).mean(axis=0)) * _UNITS / self.pixel
        return tuple(int(k) for k in self.columns if moved[k] < _UNSEEN)

    def rms_px(self, fit: _Fit) -> float:
        """Median distance of the silhouette from the outline, pixels (robust to what the
        segmentation took in or left out)."""
        return float(np.median(np.abs(fit.spread)) / self.pixel) if len(fit.spread) else float("inf")


def _nearest(x: np.ndarray, y: np.ndarray) -> np.ndarray:
    """(N,) index of the nearest of points y (M, 2) to each of x (N, 2), in blocks."""
    out = np.empty(len(x), dtype=np.int64)
    block = max(1, (1 << 22) // max(len(y), 1))
    for start in range(0, len(x), block):
        d = ((x[start:start + block, None, :] - y[None, :, :]) ** 2).sum(axis=2)
        out[start:start + block] = d.argmin(axis=1)
    return out


def _biweight_loss(r: np.ndarray, c: float) -> np.ndarray:
    """Tukey's biweight loss over c^2 / 6: quadratic near 0, 1 from |r| = c on."""
    t = np.minimum((r / c) ** 2, 1.0)
    return 1.0 - (1.0 - t) ** 3
