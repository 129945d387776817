"""Removing one object's lighting effects from the panorama (DESIGN 3, thesis chapters 3-4).

Three scales work together:
  * coarse patches over the whole room: radiosity from the panorama, reflectance, estimates
    for what the probe cannot see, and the propagation of the change for several bounces;
    the few patches whose light varies within them (under the object's contact, at its
    shadow's edge) send through sub-triangles wherever pixels take their light;
  * a fine lattice near the object: the light of the many unimportant senders and of the
    object itself, interpolated to pixels (the thesis's coarse grid of corner samples);
  * each affected pixel's own 3D point and normal: the important senders (lamps) that the
    object shadows, with exact form factors and sampled visibility.
The new radiance is the ratio form L' = L (E + dE) / E (differential rendering), so errors in
E cancel and texture is kept; only a difference image is returned.
"""
from __future__ import annotations

from dataclasses import dataclass
from typing import Callable

import numpy as np

from ..geometry import latlong
from ..geometry.clusters import cluster_triangles, visibility_samples
from ..errors import Cancelled, DimredError
from ..light.formfactor import paired_point_to_triangle
from ..geometry.mesh import Geometry, boundary_objects, build_geometry, plane_of_object, surface_keys
from ..synthesis.plane_fill import PanoramaMaps, fill_surface
from ..geometry.patches import Lattice, build_lattice, levels_for_count, levels_for_size, triangle_samples
from ..geometry.planeraster import edge_direction
from ..light.planner import neighbourhood, shadow_volume
from ..quality import Params
from ..light.radiosity import LUMA, RHO_MAX, fill_unseen, patch_radiosity, propagate, recover_reflectance
from ..geometry.raycast import Occluders, trace_panorama
from ..report import Report
from ..scene import SceneData
from ..light.split import Split
from ..synthesis.texture import SynthesisParams
from ..light.transport import Parts, Senders, make_senders, pair_visibility, transport

_MIN_COS = 0.05  # pixels seen more grazing than this count as if at this angle (area weight)
_VISIBLE = 0.2  # a patch is measured when pixels cover this share of its area


@dataclass
class RemovalResult:
    difference: np.ndarray  # (H, W, 3) float32, top row first
    edited: np.ndarray  # (H, W, 3) float32: hdri + difference
    hidden_mask: np.ndarray  # (H, W) bool: pixels that showed the object
    report: dict


def _cancel_check(cancel: Callable[[], bool] | None) -> Callable[[], None]:
    def check() -> None:
        if cancel is not None and cancel():
            raise Cancelled()

    return check


def _inset(points: np.ndarray, tris: np.ndarray) -> np.ndarray:
    """Lattice points moved a hair into their triangle: a receiver exactly on the edge between
    floor and wall sees the wall edge-on (form factor 0) while a receiver 1 mm away sees it
    fill half its hemisphere; the pixels the lattice stands for are all inside."""
    return points + 1e-3 * (tris.mean(axis=1) - points)


def _interp(values: np.ndarray, corners: np.ndarray, weights: np.ndarray) -> np.ndarray:
    return np.einsum("nk,nkc->nc", weights, values[corners])


@dataclass
class _Room:
    """The coarse radiosity solution of the room as photographed."""

    lattice: Lattice  # the room's patches come first, in the lattice's order
    patch_triangles: np.ndarray  # (P, 3, 3) each patch's triangle (one member of a cluster)
    senders: Senders
    important: np.ndarray  # (P,) bool
    visible: np.ndarray  # (P,) bool
    emitter: np.ndarray  # (P,) bool
    rho: np.ndarray  # (P, 3)
    areas: np.ndarray  # (P,)
    receivers: np.ndarray  # (R, 3) coarse receiver points
    receiver_normals: np.ndarray  # (R, 3)
    t_with: np.ndarray  # (R, P) receiver transport with the object
    t_without: np.ndarray  # (R, P) ... and without it
    patch_rows: np.ndarray  # (P, K) receiver rows whose weighted mean stands for each patch
    patch_weights: np.ndarray  # (P, K) their weights, summing to 1

    def patch_mean(self, receiver_values: np.ndarray) -> np.ndarray:
        return _interp(receiver_values, self.patch_rows, self.patch_weights)


class _Removal:
    def __init__(self, scene: SceneData, target: int, planes: list[int], params: Params, report: Report,
                 cancel: Callable[[], bool] | None):
        self.scene, self.target, self.planes, self.params, self.rep = scene, target, planes, params, report
        self.cancel = cancel
        self.check = _cancel_check(cancel)
        self.hdri = scene.hdri
        self.height, self.width = scene.hdri.shape[:2]

    # -- stages ---------------------------------------------------------------------------
    def geometry(self, geo: Geometry) -> None:
        self.geo = geo
        self.surface_key = surface_keys(geo)
        self.eps = 1e-6 * geo.scale
        self.obj_centre, self.obj_radius = geo.bounding_sphere(self.target)
        # The fine grid must resolve what the pixels show: the contact shadow where the object
        # touches the floor or a wall is a few centimetres wide, and interpolating it over coarse
        # cells darkens the pixels beside the object (E too low, so the ratio over-brightens).
        pixel = float(np.linalg.norm(self.obj_centre)) * np.pi / self.height
        self.fine_cell = min(self.obj_radius / self.params.fine_cells, self.params.fine_pixels * pixel)

    def trace(self, fill: bool = True) -> None:
        """What each pixel sees. With `fill` (a removal), the pixels around the object count as
        hidden too (they are filled, not relit), and what is behind the hidden ones is traced."""
        hits = trace_panorama(self.geo.triangles, self.width, self.height)
        self.hits = hits
        flat_tri = hits.tri.ravel()
        self.hp = np.flatnonzero(flat_tri >= 0)
        self.tri_h = flat_tri[self.hp]
        self.obj_h = self.geo.tri_object[self.tri_h]
        # A pixel on the object's silhouette mixes it with what is behind; the ratio form would
        # scale the object's share of it too, so it is filled like the pixels the object covers.
        on_object = np.zeros(self.height * self.width, dtype=bool)
        on_object[self.hp[self.obj_h == self.target]] = True
        hidden = on_object.reshape(self.height, self.width)
        if fill:
            hidden = latlong.dilate(hidden, 1)
        self.hidden_h = hidden.ravel()[self.hp]
        hidden_map = np.zeros(self.height * self.width, dtype=bool)
        hidden_map[self.hp[self.hidden_h]] = True
        self.hidden_map = hidden_map.reshape(self.height, self.width)
        self.points_h = hits.points.reshape(-1, 3)[self.hp]
        self.normals_h = self.geo.normals[self.tri_h]
        missing = len(flat_tri) - len(self.hp)
        if missing:
            self.rep.warn(f"{missing} panorama pixels see no proxy geometry (open room?); they are left unchanged")
        self.rep.info["hidden_pixels"] = int(self.hidden_h.sum())
        self.tri_without = np.full(self.height * self.width, -1, dtype=np.int64)
        self.distance_without = np.zeros(self.height * self.width)
        self.revealed = np.zeros(0, dtype=np.int64)
        if fill and self.hidden_h.any():
            # What the probe would see where the object was: the surfaces to fill.
            keep = np.flatnonzero(self.geo.tri_object != self.target)
            behind = trace_panorama(self.geo.triangles[keep], self.width, self.height)
            flat = behind.tri.ravel()
            self.tri_without[flat >= 0] = keep[flat[flat >= 0]]
            self.distance_without = behind.distance.ravel()
            hidden = np.flatnonzero(self.hidden_h)
            self.revealed = hidden[self.tri_without[self.hp[hidden]] >= 0]
            pix = self.hp[self.revealed]
            self.rev_tri = self.tri_without[pix]
            self.rev_bary = behind.bary.reshape(-1, 2)[pix]
            self.rev_points = behind.points.reshape(-1, 3)[pix]
            unseen = len(hidden) - len(self.revealed)
            if unseen:
                self.rep.warn(f"{unseen} pixels of the object see no proxy geometry behind it; they are left unchanged")

    def occluders(self) -> None:
        geo = self.geo
        seen = np.unique(self.obj_h)
        witnesses = np.concatenate([geo.triangles[np.isin(geo.tri_object, seen)].reshape(-1, 3), np.zeros((1, 3))])
        bound = boundary_objects(geo, witnesses)
        target = geo.tri_object == self.target
        self.occ_removed = Occluders(geo.triangles[target], geo.tri_object[target], self.eps)
        other = ~target & ~bound[geo.tri_object]
        self.occ_others = Occluders(geo.triangles[other], geo.tri_object[other], self.eps) if other.any() else None
        self.rep.info["occluder_objects"] = [geo.object_names[k] for k in np.unique(geo.tri_object[other])]

    def room(self) -> _Room:
        geo, prm = self.geo, self.params
        target_tri = geo.tri_object == self.target
        levels = np.ones(len(geo.triangles), dtype=np.int64)
        levels[~target_tri] = levels_for_count(geo.triangles[~target_tri], prm.patches)
        # An object of many more triangles than its patch budget is clustered instead of
        # subdivided (left out of the lattice; its patches come after the lattice's). A cluster
        # is sampled at patch_samples^2 of its triangles, so clustering pays only past that.
        obj = np.flatnonzero(target_tri)
        clustered = len(obj) > prm.object_patches * prm.patch_samples ** 2
        levels[obj] = 0 if clustered else levels_for_count(geo.triangles[obj], prm.object_patches)
        lat = build_lattice(geo.triangles, levels)
        patch_tri, areas = lat.patch_tri, geo.areas[lat.patch_tri] / levels[lat.patch_tri] ** 2
        patch_corners = lat.patch_corners
        parts = None
        if clustered:
            seen = np.isin(obj, self.tri_h)
            cl = cluster_triangles(geo.triangles[obj].mean(axis=1), geo.normals[obj], geo.areas[obj],
                                   prm.object_patches, self.obj_radius, seen)
            patch_tri = np.concatenate([patch_tri, obj[cl.representative]])
            areas = np.concatenate([areas, cl.area])
            patch_corners = np.concatenate([patch_corners, np.zeros((len(cl.area), 3), dtype=np.int64)])
            parts = Parts(geo.triangles[obj], geo.normals[obj], lat.n_patches + cl.label)
            members, member_weights = visibility_samples(cl, geo.triangles[obj].mean(axis=1), geo.areas[obj],
                                                         prm.patch_samples ** 2)
            self.rep.info["object_clusters"] = int(len(cl.area))
        ptris = np.concatenate([lat.patch_triangles(), geo.triangles[patch_tri[lat.n_patches:]]])
        pnorm = geo.normals[patch_tri]
        on_target = target_tri[patch_tri]

        # Receivers: the lattice vertices of the room (pixels interpolate between them), and the
        # centroid of every patch (a patch's mean: a vertex on the floor-wall edge would see the
        # wall fill half its hemisphere and overstate the coupling of the whole patch).
        room_vertex = ~target_tri[lat.vertex_tri]
        vertex_row = np.full(len(lat.vertices), 0, dtype=np.int64)
        vertex_row[room_vertex] = np.arange(room_vertex.sum())
        # A cluster's mean is taken over its visibility samples: its light varies over it.
        patch_rows = room_vertex.sum() + np.arange(len(areas))[:, None]
        patch_weights = np.ones((len(areas), 1))
        receivers = [_inset(lat.vertices[room_vertex], geo.triangles[lat.vertex_tri[room_vertex]]), ptris.mean(axis=1)]
        receiver_normals = [geo.normals[lat.vertex_tri[room_vertex]], pnorm]
        if clustered:
            first = room_vertex.sum() + len(areas)
            patch_rows = np.repeat(patch_rows, members.shape[1], axis=1)
            patch_weights = np.pad(patch_weights, ((0, 0), (0, members.shape[1] - 1)))
            patch_rows[lat.n_patches:] = first + np.arange(members.size).reshape(members.shape)
            patch_weights[lat.n_patches:] = member_weights / member_weights.sum(axis=1, keepdims=True)
            receivers.append(geo.triangles[obj[members]].mean(axis=2).reshape(-1, 3))
            receiver_normals.append(geo.normals[obj[members]].reshape(-1, 3))
        receivers, receiver_normals = np.concatenate(receivers), np.concatenate(receiver_normals)
        # Pixels on a clustered object take their cluster (and no lattice vertices: hidden pixels
        # are filled, not interpolated).
        in_lattice = levels[self.tri_h] > 0
        patch_h = np.zeros(len(self.hp), dtype=np.int64)
        corners_h = np.zeros((len(self.hp), 3), dtype=np.int64)
        self.weights_h = np.zeros((len(self.hp), 3))
        patch_h[in_lattice], corners_h[in_lattice], self.weights_h[in_lattice] = lat.locate(
            self.tri_h[in_lattice], self.hits.bary.reshape(-1, 2)[self.hp[in_lattice]])
        if clustered:
            tri_patch = np.zeros(len(geo.triangles), dtype=np.int64)
            tri_patch[obj] = parts.owner
            patch_h[~in_lattice] = tri_patch[self.tri_h[~in_lattice]]
        self.vertex_row = vertex_row
        self.corners_h = vertex_row[corners_h]
        self.patch_h = patch_h
        cos = np.abs(np.einsum("ij,ij->i", self.hits.directions.reshape(-1, 3)[self.hp], self.normals_h))
        guarded = int((cos < _MIN_COS).sum())
        if guarded:
            self.rep.guard("grazing_pixels_weight_capped", guarded)
        solid = np.broadcast_to(latlong.pixel_solid_angles(self.width, self.height), (self.height, self.width)).ravel()[self.hp]
        dist = self.hits.distance.ravel()[self.hp]
        weight = solid * dist**2 / np.maximum(cos, _MIN_COS)
        radiance = self.hdri.reshape(-1, 3)[self.hp].astype(np.float64)
        b, cover = patch_radiosity(radiance, patch_h, weight, areas)
        visible = cover >= _VISIBLE

        # Important senders are light sources and sunlit spots: much brighter than the typical
        # surface, ranked by power (thesis 4.3); the rest is gathered on the lattices.
        power = (b @ LUMA) * areas
        bright = (b @ LUMA) > prm.bright_factor * np.median((b @ LUMA)[visible & ~on_target])
        eligible = np.flatnonzero(visible & ~on_target & (power > 0) & bright)
        important = np.zeros(len(areas), dtype=bool)
        if len(eligible):
            order = eligible[np.argsort(-power[eligible])]
            share = np.cumsum(power[order]) / power[eligible].sum()
            count = min(int(np.searchsorted(share, prm.sender_fraction) + 1), prm.max_senders, len(order))
            important[order[:count]] = True
        imp_idx = np.flatnonzero(important)
        rest_idx = np.flatnonzero(~important)
        samples = [
            (imp_idx, triangle_samples(ptris[imp_idx], prm.sender_samples)),
            (rest_idx, ptris[rest_idx].mean(axis=1)[:, None, :]),
        ]
        senders = make_senders(ptris, pnorm, b, on_target, samples, parts)
        if clustered:
            senders.resample(lat.n_patches + np.arange(len(cl.area)), geo.triangles[obj[members]].mean(axis=2),
                             member_weights)
        self.check()
        t_with, t_without = transport(receivers, receiver_normals, senders, self.occ_removed, self.occ_others, self.check)

        # A light source outshines what it receives at every point; a patch partly under the
        # object may receive ~0 at its centroid only, so the test takes its brightest receiver.
        corner_rows = np.where(on_target[:, None], patch_rows[:, :1], vertex_row[patch_corners])
        test_rows = np.concatenate([patch_rows, corner_rows], axis=1)
        e_all = t_with @ b
        e = _interp(e_all, patch_rows, patch_weights)
        e_floor = 1e-9 * max(float((e @ LUMA).max()), 1e-30)
        keys = self.surface_key[patch_tri]
        unseen = ~visible
        for _ in range(3):
            refl = recover_reflectance(b, e, visible, e_floor, (e_all @ LUMA)[test_rows].max(axis=1))
            measured = visible & ~refl.emitter & ((e @ LUMA) > e_floor)
            rho = fill_unseen(refl.rho, measured, [keys, geo.tri_object[patch_tri]], areas)
            rho[refl.emitter] = 0.0
            b[unseen] = rho[unseen] * e[unseen]
            e_all = t_with @ b
            e = _interp(e_all, patch_rows, patch_weights)
        senders.radiosity = b
        self.rep.guard("reflectance_clamped_patches", refl.clamped)
        self.rep.guard("irradiance_near_zero_patches", refl.guarded)
        self.rep.info.update(
            patches=int(len(areas)),
            important_senders=int(important.sum()),
            emitter_patches=int(refl.emitter.sum()),
            unseen_patches=int(unseen.sum()),
            coarse_receivers=int(len(receivers)),
        )
        self.emitter_h = refl.emitter[patch_h]
        return _Room(lat, ptris, senders, important, visible, refl.emitter, rho, areas, receivers, receiver_normals,
                     t_with, t_without, patch_rows, patch_weights)

    def _seen(self, points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(N,) whether the probe (the origin) sees each point past the removed object, and
        (N,) whether it sees it at all."""
        probe = np.zeros_like(points)
        past_object = ~self.occ_removed.blocked(probe, points)
        if self.occ_others is None:
            return past_object, past_object
        return past_object, past_object & ~self.occ_others.blocked(probe, points)

    def _transport(self, points: np.ndarray, normals: np.ndarray, senders: Senders) -> tuple[np.ndarray, np.ndarray]:
        return transport(points, normals, senders, self.occ_removed, self.occ_others, self.check)

    def _sample(self, room: _Room, idx: np.ndarray, k: int):
        """k^2 points on each patch idx (n*k^2, 3), their normals, transport with and without the
        object, and whether the probe sees them past the object and at all (each (n, k^2, 1))."""
        pts = triangle_samples(room.patch_triangles[idx], k).reshape(-1, 3)
        nrm = np.repeat(room.senders.normals[idx], k * k, axis=0)
        tw, two = self._transport(pts, nrm, room.senders)
        past_object, seen = (v.reshape(len(idx), k * k, 1) for v in self._seen(pts))
        return pts, nrm, tw, two, past_object, seen

    def first_order_patches(self, room: _Room) -> tuple[np.ndarray, Split]:
        """(P, 3) first-order change of irradiance, averaged over each patch, and the split of
        those whose light varies within them (see `_split`).

        Patches near the object are sampled at k^2 points, and the samples the probe cannot see
        correct what the pixels alone got wrong for a patch partly under or behind the object:
        its reflectance is B over the E of the seen samples (B comes from visible pixels, and E
        ~ 0 under the object), and its radiosity as a sender covers the unseen part too (dark
        under the object: with B of the lit part there, taking the object away would seem to
        reveal light that was never there, on top of the light the revealed part really gets)."""
        prm = self.params
        b = room.senders.radiosity
        ptris = room.patch_triangles
        centre = ptris.mean(axis=1)
        radius = np.linalg.norm(ptris - centre[:, None, :], axis=2).max(axis=1)
        imp = np.flatnonzero(room.important)
        e = room.patch_mean(room.t_with @ b)
        near = self._significant(room, imp, centre, e, margin=radius).any(axis=1)
        near |= neighbourhood(centre, self.obj_centre, self.obj_radius + radius, prm.reach)
        refine = np.flatnonzero(near & ~room.senders.on_removed & ~room.emitter)
        self.rep.info["refined_patches"] = int(len(refine))
        if not len(refine):
            de = room.patch_mean((room.t_without - room.t_with) @ b)
            return de, self._split(room, de, [])
        pts, nrm, tw, two, past_object, seen = self._sample(room, refine, prm.patch_samples)
        n, k2 = seen.shape[:2]
        e_s = (tw @ b).reshape(n, k2, 3)
        n_seen = seen.sum(axis=1)
        e_seen = (e_s * seen).sum(axis=1) / np.maximum(n_seen, 1)
        remeasure = room.visible[refine] & (n_seen[:, 0] > 0) & ((e_seen @ LUMA) > 0.0)
        idx = refine[remeasure]
        room.rho[idx] = np.clip(b[idx] / np.maximum(e_seen[remeasure], 1e-30), 0.0, RHO_MAX)

        # Only the object's cover differs between T and T'; a centroid under the object hides
        # the patch from receivers that see most of it.
        under = ~past_object.all(axis=(1, 2)) | ~self._seen(centre[refine])[0]
        partial = refine[under]
        # groups: patches, their level k, and B and dE at the centroids of their k^2 sub-triangles.
        groups = []
        if len(partial):
            k = 2 * prm.patch_samples
            groups.append((partial, k, *self._resample(room, partial, k)))
            tw[:, partial], two[:, partial] = self._transport(pts, nrm, room.senders.subset(partial))
        de_s = ((two - tw) @ b).reshape(n, k2, 3)
        whole = refine[~under]
        groups.append((whole, prm.patch_samples, np.broadcast_to(b[whole, None, :], (len(whole), k2, 3)), de_s[~under]))
        de = room.patch_mean((room.t_without - room.t_with) @ b)
        for idx, _, _, de_g in groups:
            de[idx] = de_g.mean(axis=1)
        return de, self._split(room, de, groups)

    def _split(self, room: _Room, de: np.ndarray, groups: list[tuple[np.ndarray, int, np.ndarray, np.ndarray]]
               ) -> Split:
        """The sampled patches (groups of patches, level k, B and dE at the k^2 samples) whose
        light varies enough to matter: what the means of B and of its first change miss over the
        patch holds at least `bounce_tolerance` of the whole first change (the share where the
        propagation stops). A few patches at the object's contact and shadow edges qualify;
        important senders keep their exact per-pixel treatment."""
        db1 = room.rho * de
        db1[room.senders.on_removed | room.emitter] = 0.0
        first = float((np.abs(db1) @ LUMA * room.areas).sum())
        b = room.senders.radiosity
        keep = []
        for idx, k, b_g, de_g in groups:
            db_g = room.rho[idx, None, :] * de_g
            missed = (np.abs(b_g - b[idx, None, :]) + np.abs(db_g - db1[idx, None, :])) @ LUMA
            sel = (missed.mean(axis=1) * room.areas[idx] >= self.params.bounce_tolerance * first) & ~room.important[idx]
            keep.append((idx[sel], k, b_g[sel], db_g[sel]))
        return Split.of(room.patch_triangles, room.senders.normals, room.areas, keep)

    def _resample(self, room: _Room, idx: np.ndarray, k: int) -> np.ndarray:
        """Patches idx as senders sampled at k^2 points weighted by their light, dark where the
        probe cannot see and the estimate says so; B and the first-order change of E at those
        points (each (n, k^2, 3))."""
        b = room.senders.radiosity
        pts, nrm, tw, two, _, seen = self._sample(room, idx, k)
        e_s = (tw @ b).reshape(len(idx), k * k, 3)
        b_s = np.where(seen, b[idx, None, :], room.rho[idx, None, :] * e_s)
        b[idx] = b_s.mean(axis=1)
        room.senders.resample(idx, pts.reshape(len(idx), k * k, 3), b_s @ LUMA)
        sub = room.senders.subset(idx)
        room.t_with[:, idx], room.t_without[:, idx] = self._transport(room.receivers, room.receiver_normals, sub)
        tw[:, idx], two[:, idx] = self._transport(pts, nrm, sub)
        self.rep.info["resampled_patches"] = int(len(idx))
        return b_s, ((two - tw) @ b).reshape(len(idx), k * k, 3)

    def _sender_spheres(self, room: _Room, idx: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        tris = room.senders.triangles[idx]
        c = tris.mean(axis=1)
        return c, np.linalg.norm(tris - c[:, None, :], axis=2).max(axis=1)

    def propagate(self, room: _Room, de1: np.ndarray, split: Split) -> np.ndarray:
        """(P, 3) total radiosity change of the patches, all bounces (light sources keep theirs);
        a split patch leaves its first change to its sub-triangles (their transport to the
        coarse receivers is set)."""
        p, m = len(room.areas), len(split.parent)
        db1 = room.rho * de1
        db1[room.senders.on_removed | room.emitter] = 0.0
        db1[split.parent] = 0.0
        split.t_with, split.t_without = self._transport(room.receivers, room.receiver_normals, split.senders)

        # The sub-triangles send the first bounce only (reflectance 0): their light is gathered
        # by the patches, which carry every later bounce.
        def gather(db: np.ndarray) -> np.ndarray:
            e = room.patch_mean(room.t_without @ db[:p] + split.t_without @ db[p:])
            return np.concatenate([e, np.zeros((m, 3))])

        total, bounces = propagate(
            np.concatenate([db1, split.db]), np.concatenate([room.rho, np.zeros((m, 3))]),
            np.concatenate([room.areas, split.areas]), gather, self.params.bounce_tolerance, self.params.max_bounces,
        )
        self.rep.info["bounces"] = bounces
        self.rep.info["split_patches"] = int(len(np.unique(split.parent)))
        return total[:p]

    def _significant(self, room: _Room, imp: np.ndarray, points: np.ndarray, e_points: np.ndarray,
                     margin: float | np.ndarray = 0.0) -> np.ndarray:
        """(N, I) receiver-sender pairs where the object may cast a shadow worth computing exactly:
        inside the shadow volume, and the sender's unblocked light is at least `significance` of E."""
        imp_c, imp_r = self._sender_spheres(room, imp)
        sv = shadow_volume(points, imp_c, imp_r, self.obj_centre, self.obj_radius + np.asarray(margin))
        b_y = room.senders.radiosity[imp] @ LUMA
        area = np.linalg.norm(np.cross(room.senders.triangles[imp, 1] - room.senders.triangles[imp, 0],
                                       room.senders.triangles[imp, 2] - room.senders.triangles[imp, 0]), axis=1) / 2
        d2 = ((points[:, None, :] - imp_c[None]) ** 2).sum(axis=2) + imp_r[None] ** 2
        bound = b_y[None] * area[None] / (np.pi * d2)
        return sv & (bound >= self.params.significance * np.maximum(e_points @ LUMA, 1e-30)[:, None])

    def _irradiance(self, room: _Room, db: np.ndarray, split: Split, t: np.ndarray, t_w: np.ndarray,
                    ts: np.ndarray, ts_w: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(E, E') at receivers with transport t, t_w from the patches and ts, ts_w from the
        split patches' sub-triangles (with and without the object): the room as photographed,
        and after removal with every bounce of the change db (P, 3)."""
        rest = split.rest(room.senders.radiosity)
        return t @ rest + ts @ split.b, t_w @ (rest + db) + ts_w @ (split.b + split.db)

    def _fine_transport(self, room: _Room, tri: np.ndarray, bary: np.ndarray, db: np.ndarray, split: Split):
        """Transport with the object at the vertices of a fine lattice (cells of about
        `fine_cell`) over the triangles `tri`, only the vertices that the points
        (tri, bary) interpolate from, and `_irradiance` there: (T, T', E, E', corner rows (N, 3),
        weights (N, 3))."""
        geo = self.geo
        tris_r = np.unique(tri)
        levels = np.zeros(len(geo.triangles), dtype=np.int64)
        levels[tris_r] = levels_for_size(geo.triangles[tris_r], self.fine_cell, max_level=512)
        fine = build_lattice(geo.triangles, levels)
        _, corners, weights = fine.locate(tri, bary)
        needed, inverse = np.unique(corners, return_inverse=True)
        self.check()
        points = _inset(fine.vertices[needed], geo.triangles[fine.vertex_tri[needed]])
        normals = geo.normals[fine.vertex_tri[needed]]
        tf, tf_w = self._transport(points, normals, room.senders)
        e, e_after = self._irradiance(room, db, split, tf, tf_w, *self._transport(points, normals, split.senders))
        return tf, tf_w, e, e_after, inverse.reshape(corners.shape), weights

    def local(self, room: _Room, db: np.ndarray, split: Split) -> tuple[np.ndarray, np.ndarray]:
        """Per-pixel E and dE after removal (every bounce of the change db (P, 3)), exact where
        the object's shadow of a light falls."""
        prm = self.params
        b = room.senders.radiosity
        imp = np.flatnonzero(room.important)

        # The important senders' change is added per pixel below, exactly where it matters.
        def change(e: np.ndarray, e_after: np.ndarray, t: np.ndarray, t_w: np.ndarray) -> np.ndarray:
            return e_after - e - (t_w - t)[:, imp] @ b[imp]

        e_v, ea_v = self._irradiance(room, db, split, room.t_with, room.t_without, split.t_with, split.t_without)
        e_pix = _interp(e_v, self.corners_h, self.weights_h)
        de_pix = _interp(change(e_v, ea_v, room.t_with, room.t_without), self.corners_h, self.weights_h)

        cand = ~self.hidden_h & ~self.emitter_h
        if self.planes:
            cand &= np.isin(self.obj_h, self.planes)
        ci = np.flatnonzero(cand)
        sig = self._significant(room, imp, self.points_h[ci], e_pix[ci])
        near = neighbourhood(self.points_h[ci], self.obj_centre, self.obj_radius, prm.reach)
        self.rep.info["affected_pixels"] = int((sig.any(axis=1) | near).sum())
        if not (sig.any() or near.any()):
            self.rep.skip("local", "the object neither shadows nor lights any visible surface")
            return e_pix, de_pix

        # Base for the pixel: the coarse lattice, or near the object a fine one (only the
        # vertices the pixels use): the split patches' sub-triangles beside the object light
        # the pixels near them unevenly, which coarse vertices would smear over a coarse patch.
        pr, ps = np.nonzero(sig)
        s = imp[ps]
        pix = ci[pr]
        lattice_e = (self.weights_h[pix] * room.t_with[self.corners_h[pix], s[:, None]]).sum(axis=1)
        ni = ci[near]
        if len(ni):
            tf, tf_w, e_f, ea_f, inverse, weights = self._fine_transport(
                room, self.tri_h[ni], self.hits.bary.reshape(-1, 2)[self.hp[ni]], db, split)
            self.rep.info["fine_vertices"] = int(len(tf))
            e_pix[ni] = _interp(e_f, inverse, weights)
            de_pix[ni] = _interp(change(e_f, ea_f, tf, tf_w), inverse, weights)
            row = np.full(len(self.hp), -1)
            row[ni] = np.arange(len(ni))
            in_fine = row[pix] >= 0
            k = row[pix[in_fine]]
            lattice_e[in_fine] = (weights[k] * tf[inverse[k], s[in_fine, None]]).sum(axis=1)

        f = paired_point_to_triangle(self.points_h[pix], self.normals_h[pix], room.senders.triangles[s],
                                     room.senders.normals[s])
        vis, vis_w = pair_visibility(self.points_h, room.senders, pix, s, self.occ_removed, self.occ_others, self.check)
        np.add.at(e_pix, pix, (f * vis - lattice_e)[:, None] * b[s])
        np.add.at(de_pix, pix, (f * (vis_w - vis))[:, None] * b[s])
        self.rep.info["exact_pairs"] = int(len(s))
        return e_pix, de_pix

    def fill_hidden(self, room: _Room, e_pix: np.ndarray, db: np.ndarray, split: Split,
                    show: Callable[[np.ndarray], None] | None = None) -> np.ndarray:
        """(N, 3) radiance change of the revealed pixels (those that saw the object and see a
        surface once it is gone): synthesised reflectance lit by the irradiance after removal.

        `show(change)` gets the revealed pixels' change as the fill refines: first with each
        patch's mean reflectance, then after every synthesis level of every surface."""
        geo, prm = self.geo, self.params
        b = room.senders.radiosity
        tri, bary, points = self.rev_tri, self.rev_bary, self.rev_points
        _, _, _, e_after, inverse, weights = self._fine_transport(room, tri, bary, db, split)
        patch, _, _ = room.lattice.locate(tri, bary)
        e_new = _interp(e_after, inverse, weights)
        e_new = np.maximum(e_new, 0.0)

        keys = self.surface_key
        n = self.height * self.width
        surface_with = np.full(n, -1, dtype=np.int64)
        surface_with[self.hp] = keys[self.tri_h]
        has = self.tri_without >= 0
        surface_without = np.where(has, keys[np.maximum(self.tri_without, 0)], -1)
        shape = (self.height, self.width)
        maps = PanoramaMaps(surface_with.reshape(shape), self.hits.distance, surface_without.reshape(shape),
                            self.distance_without.reshape(shape), self.hidden_map)
        radiance = self.hdri.reshape(-1, 3)[self.hp].astype(np.float64)
        e_ref = float(np.median(e_pix @ LUMA))
        measured = ~self.hidden_h & ~self.emitter_h & ((e_pix @ LUMA) > 1e-3 * e_ref)
        rho_flat = np.zeros((n, 3))
        rho_flat[self.hp[measured]] = np.clip(np.pi * radiance[measured] / e_pix[measured], 0.0, RHO_MAX)
        valid = np.zeros(n, dtype=bool)
        valid[self.hp[measured]] = True
        rho_image, valid = rho_flat.reshape(*shape, 3), valid.reshape(shape)

        # Raster cells about as large as the panorama's pixels where the object was.
        pix = self.hp[self.revealed]
        solid = np.broadcast_to(latlong.pixel_solid_angles(self.width, self.height), shape).ravel()[pix]
        cos = np.abs(np.einsum("ij,ij->i", self.hits.directions.reshape(-1, 3)[pix], geo.normals[tri]))
        footprint = np.sqrt(solid * self.distance_without[pix] ** 2 / np.maximum(cos, _MIN_COS))
        cell = float(np.median(footprint)) * prm.raster_cell
        synth = SynthesisParams(neighbourhood=prm.synth_neighbourhood, levels=prm.synth_levels,
                                generations=prm.synth_generations)
        rho = room.rho[patch].copy()
        emit = room.emitter[patch]

        def change() -> np.ndarray:
            new = rho * e_new / np.pi
            # A light behind the object shines on with the radiosity its patch was given.
            new[emit] = b[patch[emit]] / np.pi
            return new - radiance[self.revealed]

        if show is not None:
            show(change())
        surfaces = []
        for key in np.unique(keys[tri]):
            sel = np.flatnonzero(keys[tri] == key)
            self.check()

            def level_shown(level_rho: np.ndarray, sel: np.ndarray = sel) -> None:
                rho[sel] = level_rho
                show(change())

            normal = geo.normals[tri[sel[0]]]
            along = edge_direction(geo.triangles[keys == key], normal)
            got = fill_surface(maps, rho_image, valid, int(key), normal, points[sel], cell,
                               prm.exemplar_margin, synth, seed=prm.seed, cancel=self.cancel,
                               progress=None if show is None else level_shown, along=along)
            name = geo.object_names[geo.tri_object[tri[sel[0]]]]
            if got.known_cells:
                rho[sel] = got.rho
            if not got.synthesised:
                self.rep.warn(f"too little of '{name}' is seen around the object to synthesise its texture: "
                              f"{len(sel)} pixels get its mean reflectance")
            surfaces.append(dict(surface=name, pixels=int(len(sel)), raster=list(got.raster_shape),
                                 cell=round(got.cell, 5), known_cells=got.known_cells,
                                 hole_cells=got.hole_cells, synthesised=got.synthesised))
        self.rep.info["filled_surfaces"] = surfaces
        return change()

    def compose(self, e_pix: np.ndarray, de_pix: np.ndarray) -> np.ndarray:
        """(N, 3) radiance change of the hit pixels from the ratio form, with guards counted."""
        radiance = self.hdri.reshape(-1, 3)[self.hp].astype(np.float64)
        apply = ~self.hidden_h & ~self.emitter_h
        e_ref = float(np.median(e_pix[apply] @ LUMA)) if apply.any() else 0.0
        dark = (e_pix @ LUMA) <= 1e-6 * max(e_ref, 1e-30)
        self.rep.guard("irradiance_near_zero_pixels", int((apply & dark & (np.abs(de_pix) @ LUMA > 0)).sum()))
        apply &= ~dark
        e = np.maximum(e_pix, 1e-30)
        implied = np.pi * radiance / e
        over = implied > RHO_MAX
        self.rep.guard("reflectance_clamped_pixels", int((apply & over.any(axis=1)).sum()))
        e_eff = np.where(over, np.pi * radiance / RHO_MAX, e)
        d = np.where(apply[:, None], radiance * de_pix / np.maximum(e_eff, 1e-30), 0.0)
        negative = radiance + d < 0.0
        self.rep.guard("negative_radiance_clamped", int(negative.any(axis=1).sum()))
        d = np.where(negative, -radiance, d)
        return d


@dataclass
class Solution:
    """A removal's solved lighting before the panorama is edited: the job (geometry, hits),
    the room's radiosity, the change db of its patches with every bounce, the split patches,
    and per hit pixel (`job.hp`) E with the object and the change dE once it is gone."""

    job: _Removal
    room: _Room
    db: np.ndarray
    split: Split
    e_pix: np.ndarray
    de_pix: np.ndarray

    def irradiance(self, tri: np.ndarray, bary: np.ndarray) -> np.ndarray:
        """(N, 3) E with the object in place at the points (geometry triangle, barycentric
        weights of vertices 1 and 2), on a fine lattice over those triangles: points on the
        object itself too, which the pixel stages leave out."""
        _, _, e, _, inverse, weights = self.job._fine_transport(self.room, tri, bary, self.db, self.split)
        return np.maximum(_interp(e, inverse, weights), 0.0)


def solve(scene: SceneData, object_name: str, planes: list[str] | tuple[str, ...], params: Params, rep: Report,
          cancel: Callable[[], bool] | None = None, traced: Callable[[_Removal], None] | None = None,
          fill: bool = True) -> Solution:
    """Every stage of the removal up to the new irradiance of each pixel (DESIGN 3, steps 1-5
    and 8); the stages are timed in `rep`. `traced(job)` is called once the pixels are traced,
    before the panorama is read as radiosity (it may change `job.hdri`). Without `fill` (an
    insertion has nothing to fill) the pixels around the object are relit like the rest."""
    check = _cancel_check(cancel)
    if object_name not in scene.object_names:
        raise DimredError(f"no mesh object named '{object_name}' among the scene's proxy geometry")
    target = scene.object_names.index(object_name)
    with rep.stage("geometry"):
        geo = build_geometry(scene.triangles, scene.tri_object, scene.object_names, scene.center, scene.rotation)
        if not (geo.tri_object == target).any():
            raise DimredError(f"'{object_name}' has no faces to remove")
        plane_ids = []
        for name in planes:
            if name not in geo.object_names:
                raise DimredError(f"no mesh object named '{name}' for --plane")
            idx = geo.object_names.index(name)
            if plane_of_object(geo, idx) is None:
                raise DimredError(f"'{name}' is not planar: --plane takes flat surfaces only")
            plane_ids.append(idx)
        rep.guard("degenerate_triangles_dropped", geo.dropped_degenerate)
    job = _Removal(scene, target, plane_ids, params, rep, cancel)
    job.geometry(geo)
    with rep.stage("trace"):
        job.trace(fill)
    if traced is not None:
        traced(job)
    check()
    with rep.stage("occluders"):
        job.occluders()
    with rep.stage("radiosity"):
        room = job.room()
    check()
    with rep.stage("first_order"):
        de1, split = job.first_order_patches(room)
    with rep.stage("propagation"):
        db = job.propagate(room, de1, split)
    check()
    with rep.stage("local"):
        e_pix, de_pix = job.local(room, db, split)
    return Solution(job, room, db, split, e_pix, de_pix)


def finish(solution: Solution, rep: Report, preview: Callable[[np.ndarray], None] | None = None) -> RemovalResult:
    """The edited panorama from a solved removal: the ratio form on the pixels that keep their
    surface, texture synthesis where the object was (see `remove`)."""
    job, room, db, split = solution.job, solution.room, solution.db, solution.split
    with rep.stage("compose"):
        d = job.compose(solution.e_pix, solution.de_pix)

    def difference_image(d_revealed: np.ndarray) -> np.ndarray:
        d[job.revealed] = d_revealed
        image = np.zeros((job.height * job.width, 3), dtype=np.float32)
        image[job.hp] = d
        return image.reshape(job.height, job.width, 3)

    if len(job.revealed):
        show = None if preview is None else lambda d_revealed: preview(difference_image(d_revealed))
        with rep.stage("synthesis"):
            d_revealed = job.fill_hidden(room, solution.e_pix, db, split, show)
    else:
        d_revealed = np.zeros((0, 3))
        rep.skip("synthesis", "the object is not visible from the probe centre: no hidden region to fill"
                 if not job.hidden_h.any() else "nothing is behind the object to fill")
    difference = difference_image(d_revealed)
    edited = (job.hdri + difference).astype(np.float32)
    rep.info["hidden_region_filled"] = bool(len(job.revealed) == job.hidden_h.sum())
    return RemovalResult(difference=difference, edited=edited, hidden_mask=job.hidden_map, report=rep.as_dict())


def remove(
    scene: SceneData,
    object_name: str,
    planes: list[str] | tuple[str, ...] = (),
    params: Params | None = None,
    progress: Callable[[str, float], None] | None = None,
    cancel: Callable[[], bool] | None = None,
    preview: Callable[[np.ndarray], None] | None = None,
) -> RemovalResult:
    """Remove `object_name`'s shadows and reflected light from the scene's panorama.

    `preview(difference)` gets (H, W, 3) float32 difference images before the result: the
    lighting corrected with the hidden region roughly filled, then refined level by level."""
    rep = Report(progress, stages=8)
    return finish(solve(scene, object_name, planes, params or Params(), rep, cancel), rep, preview)
