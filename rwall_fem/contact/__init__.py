"""Contact between the parts of the body and of a part with itself (Radioss /INTER/TYPE7).

:func:`build_contacts` turns a scene's ``[[contact]]`` tables into
:class:`~rwall_fem.contact.interface.ContactInterface` forces of the step: the main
segments are the boundary faces of the main parts (:mod:`~rwall_fem.contact.surface`),
the secondary nodes the nodes of the secondary parts' boundary faces; a symmetric
interface also runs the other way; a self-contact (``self = true``) runs the main parts'
nodes against their own faces, each node kept off the faces that hold it.
In a body whose cells may erode, the surfaces of the parts that may erode follow the
erosion (:mod:`~rwall_fem.contact.erosion`): faces of eroded solid cells leave and bared
faces join; eroded shells leave.

On a body of shells the segments are the shells, both sides active
(:func:`~rwall_fem.contact.surface.shell_surface`); without a given ``gap`` the gap is
variable, as Radioss's Igap 3: a node against a segment gets half the thickness of the
thickest shell at the node plus half the segment's (half the sum of the thicknesses),
scaled by ``gap_scale``, at most ``gap_size_share`` x the sum of the shortest sides of the
node's shells and of the segment, and at most ``gap_max`` (Radioss Igap 3's bounds of the
pair, ``i7cor3.F``: :class:`GapShare`), floored at Radioss's default Gapmin,
min(thinnest shell, half the shortest side). A given ``gap`` is
constant (Radioss Igap 0). The penalty stiffness of each segment is bounded by
``stiffness_min`` and ``stiffness_max`` (Radioss Stmin, Stmax).

The faces of solid parts on a symmetry plane (a plane x_c = const whose nodes a
``[[boundary]]`` holds at zero velocity in c) are left out of the surfaces
(:func:`~rwall_fem.contact.surface.held_plane_faces`); their nodes stay secondary nodes.
Shells are cut along their sides (:func:`~rwall_fem.contact.surface.held_plane_sides`: the
nodes held in c have their rotations about the two other axes held too) and stay segments.
The nodes on the planes act with their share of the whole node (:func:`_mirror`).
"""

from __future__ import annotations

import logging
import math
from dataclasses import dataclass, field

import numpy as np
from mpi4py import MPI

from rwall_fem.contact.erosion import (
    ErodingContact,
    ErodingShells,
    ErodingSurface,
    may_erode,
)
from rwall_fem.contact.interface import ContactInterface, Pass
from rwall_fem.contact.surface import (
    Surface,
    held_plane_faces,
    held_plane_sides,
    part_surface,
    shell_surface,
)

__all__ = ["build_contacts"]


def build_contacts(scene, solid, state, internal=None) -> list[ContactInterface]:
    """The contact interfaces of ``scene`` on the body of ``solid`` (``build._Solid``),
    acting on ``state``, whose cells erode as those of ``internal`` (the
    :class:`~rwall_fem.body.Body` of the step; default: the solid's);
    :class:`~rwall_fem.scene.SceneError` (one line, on every rank)
    for a part the body does not have, a side without faces, a key of the variable gap on
    a body of solids, or a gap not smaller than a part."""
    from rwall_fem.scene import SceneError
    from rwall_fem.scene.keys import did_you_mean
    from rwall_fem.walls.constraint import filter_alpha

    body, comm = solid.elastic, solid.comm
    faces = shell_surface if solid.shells else part_surface
    names = [part.name for part in solid.parts]
    owned = solid.V.dofmap.index_map.local_to_global(np.arange(solid.owned, dtype=np.int32))
    surfaces: dict[str, Surface] = {}
    eroding: dict[str, ErodingSurface] = {}  # the parts whose cells may erode
    interfaces, all_nodes = [], []  # and the surface nodes of each (global numbers)
    held = _held_at_rest(scene, solid)
    # The faces of each solid part left out, on symmetry planes (shells: the sides on
    # them), and the axes of their planes
    cut: dict[str, Surface] = {}
    axes: dict[str, np.ndarray] = {}

    def _total(parts: tuple[str, ...]) -> Surface:
        """The faces of ``parts`` now, part after part."""
        found = [eroding[n].surface if n in eroding else surfaces[n] for n in dict.fromkeys(parts)]
        total = found[0]
        for more in found[1:]:
            total = total + more
        return total

    for i, spec in enumerate(scene.contacts):
        where = f"{scene.source}: contact[{i}]"
        share = GapShare.of(spec)
        if share.scene_keys() and not solid.shells:
            raise SceneError(f"{where}.{share.scene_keys()[0]}: shapes the variable gap of "
                             "shells; a body of solids has a constant gap (gap, default 0.1 x "
                             "the shortest edge): leave it out")  # fmt: skip

        def side(key: str, parts: tuple[str, ...]) -> Surface:
            for name in parts:
                if name not in names:
                    raise SceneError(
                        f"{where}.{key}: the body has no part {name!r}"
                        f"{did_you_mean(name, names)}; its parts: {', '.join(names)}"
                    )
            for name in parts:
                k = names.index(name)
                if name in surfaces or name in eroding:
                    continue
                if may_erode(scene, body.parts[k]):
                    force = (internal or body).elements[k]
                    if solid.shells:
                        eroding[name] = ErodingShells(body, k, comm, force)
                    else:
                        eroding[name] = ErodingSurface(body, k, comm, force, held)
                    if held is not None and not solid.shells:
                        cut[name], axes[name] = eroding[name].cut, eroding[name].axes
                else:
                    surfaces[name] = faces(body, k, comm)
                    if held is not None and not solid.shells:
                        axis = held_plane_faces(surfaces[name], *held)
                        cut[name], axes[name] = surfaces[name].select(axis >= 0), axis[axis >= 0]
                        surfaces[name] = surfaces[name].select(axis < 0)
                if held is not None and solid.shells:
                    cut[name], axes[name] = held_plane_sides(body, k, comm, held)
            total = _total(parts)
            if not len(total.segments):
                raise SceneError(f"{where}.{key}: the parts {', '.join(parts)} have no "
                                 "boundary face")  # fmt: skip
            return total

        if spec.single_surface:
            main = spec.main or tuple(names)
            side("main", main)
            sides = [(main, main)]
        else:
            main, secondary = spec.main, spec.secondary
            side("main", main), side("secondary", secondary)
            sides = [(secondary, main)] + ([(main, secondary)] if spec.symmetric else [])
        parts = {name: None for pair in sides for name in pair[0] + pair[1]}  # both sides
        here = [eroding[name] for name in parts if name in eroding]
        start = [(_total(a), _total(b)) for a, b in sides]
        nodes = np.unique(np.concatenate([s.nodes for pair in start for s in pair]
                                         + [s.nodes for s in here]))  # fmt: skip
        edge = float(min(s.edge.min() for pair in start for s in pair))
        half = float(max(-s.depth.min(initial=0.0) for pair in start for s in pair))
        node_gap, node_size = _node_gaps(nodes, [s for pair in start for s in pair], share)
        gap = spec.gap if spec.gap is not None else _gap_floor(start, edge, share.scale)
        variable = spec.gap is None and half > 0.0
        removal = None
        if spec.exclude_within_gap:
            removal = _Removal(_start_positions(solid, owned, nodes), node_gap, node_size,
                               variable, gap, share.most)  # fmt: skip

        def passes(sides=sides, nodes=nodes, spec=spec, share=share,
                   removal=removal) -> list[Pass]:  # fmt: skip
            """The passes of the interface from its sides' surfaces as they are."""
            out = []
            for sec_parts, seg_parts in sides:
                sec, seg = _total(sec_parts), _total(seg_parts)
                out.append(Pass(
                    np.searchsorted(nodes, sec.nodes).astype(np.int64),
                    np.where(seg.segments >= 0, np.searchsorted(nodes, seg.segments), -1),
                    _bounded_stiffness(spec, seg.stiffness), _scaled_depth(seg, share),
                    _segment_sizes(seg, share),
                ))  # fmt: skip
                if removal is not None:
                    out[-1].removed = removal.lists(out[-1], len(out) - 1)
            return out

        common = dict(
            gap=gap, friction=spec.friction, alpha=filter_alpha(spec.friction_filter, state.dt),
            margin=edge, state=state, comm=comm, owned_global=owned, damping=spec.damping,
        )  # fmt: skip
        if here:
            interface = ErodingContact(f"contact[{i}]", nodes, here, passes, **common)
        else:
            interface = ContactInterface(f"contact[{i}]", nodes, passes(), **common)
        if variable:
            interface.vary_gap(node_gap, node_size, nodes, share.most)
        interface.start(state)
        left_out = {name: len(cut[name].segments) for name in parts
                    if name in cut and len(cut[name].segments)}  # fmt: skip
        if left_out:
            _mirror(interface, nodes, [(cut[name], axes[name]) for name in left_out])
            logging.getLogger("rwall_fem").info(
                "%s: %s on symmetry planes: %s", interface.name,
                "shell sides" if solid.shells else "faces left out of the surface",
                ", ".join(f"{n} {name}" for name, n in left_out.items()))  # fmt: skip
        gap = interface.gap_max  # the largest of a variable gap
        for key, parts in (("main", spec.main or tuple(names)), ("secondary", spec.secondary)):
            for name in parts:
                extent = np.sort(interface.extent(_total((name,)).nodes))
                # A flat sheet has no extent across: its width then
                smallest = float(extent[1] if solid.shells else extent[0])
                across, default = (("narrowest", "half the sum of the thicknesses")
                                   if solid.shells else
                                   ("thinnest", "0.1 x the shortest edge"))  # fmt: skip
                if gap >= smallest:
                    raise SceneError(
                        f"{where}.gap: {gap:g} m is not smaller than part {name!r} "
                        f"({smallest:g} m across at its {across}): the gap must be a small "
                        f"fraction of the parts (default {default})"
                    )
        interfaces.append(interface)
        all_nodes.append(nodes)
    if interfaces:
        # The step of a node held by cells and contact springs, node by node: the cells'
        # term, from the cells at some surface node (every node of an eroding part's).
        imap = solid.V.dofmap.index_map
        rows = np.arange(imap.size_local + imap.num_ghosts, dtype=np.int32)
        surface = np.isin(imap.local_to_global(rows), np.concatenate(all_nodes))
        element = (internal or body).track_nodal_stiffness(surface)
        for interface in interfaces:
            interface.combine_with(element)
    return interfaces


def _start_positions(solid, owned: np.ndarray, nodes: np.ndarray) -> np.ndarray:
    """The positions at the start (m, rows of 3) of the surface nodes ``nodes`` (global
    numbers, sorted), from every rank (collective)."""
    mine = np.flatnonzero(np.isin(owned, nodes))
    pieces = solid.comm.allgather((owned[mine], solid.X[mine]))
    ids = np.concatenate([p[0] for p in pieces])
    x = np.concatenate([np.asarray(p[1]).reshape(-1, 3) for p in pieces])
    return np.ascontiguousarray(x[np.argsort(ids)][np.searchsorted(np.sort(ids), nodes)])


@dataclass
class _Removal:
    """Radioss Irem_gap 2 (``exclude_within_gap``): the nodes each segment of a pass leaves
    out of its search, those within sqrt 2 x their pair gap of it along the mesh
    (``kernels/contact_remove.c``), from the surface nodes' positions at the start
    ``positions`` (m), their thickness and size shares ``node_gap``, ``node_size`` (m) of a
    ``variable`` gap, the constant gap (or the variable one's floor) ``gap`` and its bound
    ``most`` (m).

    Built once, as Radioss builds them in its starter: the first lists of each pass (its
    surfaces at the start) are kept, by segment, and a pass built again after erosion
    gives each segment it had at the start that segment's start list; only the faces that
    erosion bared get lists of their own, by the same rule on the surface as it is then
    (without the eroded cells' faces a walk along the mesh would find longer ways round
    the holes, and a node across a crack would become a contact of the segments beside
    it)."""

    positions: np.ndarray
    node_gap: np.ndarray
    node_size: np.ndarray
    variable: bool
    gap: float
    most: float
    start: list = field(default_factory=list)  # per pass: segment keys, offsets, nodes

    def lists(self, ps: Pass, which: int) -> tuple[np.ndarray, np.ndarray]:
        """The lists of pass ``ps``, the ``which``-th of its interface (over the surface
        nodes), as :attr:`Pass.removed`."""
        keys = _segment_keys(ps.segments)
        if which == len(self.start):  # the pass at the start
            offsets, removed = self._walk(ps)
            order = np.argsort(keys)
            self.start.append((keys[order], order, offsets, removed))
            return offsets, removed
        known, order, start_offsets, start_removed = self.start[which]
        at = np.minimum(np.searchsorted(known, keys), max(len(known) - 1, 0))
        kept = known[at] == keys if len(known) else np.zeros(len(keys), dtype=bool)
        where, counts = np.zeros(len(keys), dtype=np.int64), np.zeros(len(keys), dtype=np.int64)
        was = order[at[kept]]
        where[kept] = start_offsets[was]
        counts[kept] = start_offsets[was + 1] - start_offsets[was]
        pool = start_removed
        if not kept.all():  # faces bared by erosion: their lists on the surface as it is
            offsets, removed = self._walk(ps)
            new = ~kept
            where[new] = len(pool) + offsets[:-1][new]
            counts[new] = np.diff(offsets)[new]
            pool = np.concatenate([pool, removed])
        ends = np.cumsum(counts)
        rows = np.arange(int(ends[-1]) if len(ends) else 0) + np.repeat(where - ends + counts,
                                                                         counts)
        return np.concatenate([[0], ends]).astype(np.int64), pool[rows].copy()

    def _walk(self, ps: Pass) -> tuple[np.ndarray, np.ndarray]:
        """The lists of pass ``ps`` by the walk along its own segments."""
        from rwall_fem.kernels import load

        ffi, lib = load()
        p = ffi.from_buffer
        n, segs = len(self.positions), np.ascontiguousarray(ps.segments, dtype=np.int64)
        secondary = np.zeros(n, dtype=np.int8)
        secondary[ps.secondary] = 1
        seg_gap = np.ascontiguousarray(np.where(ps.depth < 0.0, -ps.depth, 0.0))
        seg_size = np.ascontiguousarray(ps.size, dtype=np.float64)
        offsets = np.zeros(len(segs) + 1, dtype=np.int64)
        removed = np.zeros(8 * len(segs) + 1, dtype=np.int64)
        while True:
            count = lib.contact_remove_lists(
                len(segs), p("int64_t[]", segs), n, p("double[]", self.positions),
                p("int8_t[]", secondary), p("double[]", seg_gap), p("double[]", seg_size),
                p("double[]", self.node_gap), p("double[]", self.node_size),
                int(self.variable), self.gap, self.most, len(removed),
                p("int64_t[]", offsets), p("int64_t[]", removed),
            )  # fmt: skip
            if count <= len(removed):
                return offsets, removed[:count].copy()
            removed = np.zeros(count, dtype=np.int64)


def _segment_keys(segments: np.ndarray) -> np.ndarray:
    """Each segment (a row of 4 node indices, -1 as a triangle's 4th) as one value, the
    same whatever the order of its nodes."""
    rows = np.ascontiguousarray(np.sort(segments, axis=1), dtype=np.int64)
    return rows.view(np.dtype((np.void, 32))).ravel()


def _mirror(interface, nodes: np.ndarray, planes: list[tuple[Surface, np.ndarray]]) -> None:
    """Let ``interface`` (over the surface nodes ``nodes``) act as in the whole model of a
    model cut by symmetry planes: each node of the faces left out or shell sides on the
    planes (``planes``: those and the axes of their planes) is on those planes, and holds
    1/2 of the whole node per plane (``kernels/contact.c``, mirror)."""
    on = np.zeros(len(nodes), dtype=np.int8)
    for faces, axis in planes:
        ids = faces.segments
        bits = np.repeat((1 << axis).astype(np.int8), 4)
        ids, bits = ids.ravel(), bits[ids.ravel() >= 0]
        ids = ids[ids >= 0]
        rows = np.minimum(np.searchsorted(nodes, ids), len(nodes) - 1)
        here = nodes[rows] == ids
        np.bitwise_or.at(on, rows[here], bits[here])
    count = sum((on >> c) & 1 for c in range(3))
    share = np.ascontiguousarray(0.5**count, dtype=np.float64)
    interface.mirror(share, on, nodes)


def _held_at_rest(scene, solid) -> tuple[np.ndarray, np.ndarray, np.ndarray] | None:
    """The nodes that ``[[boundary]]`` tables hold at zero velocity in some component c
    (on shells, with their rotations about the two other axes held: a symmetry plane's
    condition), the same on every rank: their global numbers (sorted), positions (m) and
    held components (rows of 3 booleans); None without such a table."""
    from rwall_fem.meshing import group_nodes

    held = np.zeros((solid.owned, 3), dtype=bool)
    turns = np.zeros((solid.owned, 3), dtype=bool)  # the rotations held (shells)
    for spec in scene.boundaries:
        v = np.asarray(spec.velocity, dtype=float)
        rest = np.all(v[:, 1:] == 0.0, axis=0) if v.ndim == 2 else v == 0.0
        nodes = group_nodes(solid.V, solid.body, spec.group)
        nodes = nodes[nodes < solid.owned]
        for c in spec.components:
            held[nodes, "xyz".index(c)] |= bool(rest["xyz".index(c)])
        for c in spec.rotations or "":
            turns[nodes, "xyz".index(c)] = True
    if solid.shells:
        held &= np.roll(turns, -1, axis=1) & np.roll(turns, -2, axis=1)
    if not solid.comm.allreduce(bool(held.any()), op=MPI.LOR):
        return None
    mine = np.flatnonzero(held.any(axis=1))
    ids = solid.V.dofmap.index_map.local_to_global(mine.astype(np.int32))
    pieces = solid.comm.allgather((ids, solid.X[mine], held[mine]))
    ids = np.concatenate([p[0] for p in pieces])
    order = np.argsort(ids)
    return (ids[order], np.concatenate([p[1] for p in pieces]).reshape(-1, 3)[order],
            np.concatenate([p[2] for p in pieces]).reshape(-1, 3)[order])  # fmt: skip


def _gap_floor(sides, edge: float, scale: float = 1.0) -> float:
    """The default (constant, or the floor of a variable) gap (m): Radioss's Gapmin,
    min(thinnest shell x ``scale``, half the shortest side) with shells (``i7sti3.F``:
    the thickness scaled by Fscalegap, the floor not bounded by Gap_max), 0.1 x the
    shortest edge of solids' faces."""
    thickness = [2.0 * -s.depth[s.depth < 0.0] for pair in sides for s in pair]
    thickness = np.concatenate(thickness)
    return min(scale * float(thickness.min()), 0.5 * edge) if len(thickness) else 0.1 * edge


# A pair's variable gap is at most this fraction of the sum of the shortest sides of the
# node's shells and of the segment (Radioss TYPE7 Igap 3's default %mesh_size, i7sti3.F;
# LS-DYNA's automatic contacts alike): a node then stays clear of its own flat sheet
# beyond its neighbouring segments. A scene's ``gap_size_share`` (a deck's %mesh_size)
# changes it.
SIZE_SHARE = 0.4


@dataclass(frozen=True)
class GapShare:
    """How the shells' half thicknesses t/2 make a pair's variable gap (Radioss TYPE7
    Igap 3, ``i7sti3.F``, ``i7cor3.F``): each side's thickness share scale x t/2 (GAP_S,
    GAP_M) and size share size x its shortest side (GAP_S_L, GAP_M_L: a node's, the least
    over its shells), the pair's gap min(sum of the thickness shares, sum of the size
    shares, ``most``) (m; ``most`` the scene's ``gap_max``, inf: none), never below the
    floor."""

    scale: float = 1.0
    size: float = SIZE_SHARE
    most: float = math.inf

    @classmethod
    def of(cls, spec) -> GapShare:
        """The share of the ``[[contact]]`` table ``spec``."""
        most = math.inf if spec.gap_max is None else spec.gap_max
        return cls(spec.gap_scale, spec.gap_size_share, most)

    def scene_keys(self) -> list[str]:
        """The ``[[contact]]`` keys that make this share differ from the default one."""
        default = GapShare()
        return [key for key, given, usual in (("gap_scale", self.scale, default.scale),
                                              ("gap_max", self.most, default.most),
                                              ("gap_size_share", self.size, default.size))
                if given != usual]  # fmt: skip


def _bounded_stiffness(spec, stiffness: np.ndarray) -> np.ndarray:
    """The penalty stiffness k0 (N/m) of segments whose elements give ``stiffness``:
    scaled by ``stiffness_scale`` (Radioss Stfac), then within [stiffness_min,
    stiffness_max] (Radioss Stmin, Stmax: ``i7cor3.F``, STIF = max(KMIN, min(STIF, KMAX)))."""
    high = np.inf if spec.stiffness_max is None else spec.stiffness_max
    return np.clip(spec.stiffness_scale * stiffness, spec.stiffness_min, high)


def _scaled_depth(s: Surface, share: GapShare = GapShare()) -> np.ndarray:
    """The depths of the segments of ``s`` (m) with each shell's thickness share of a
    variable gap (-depth, half its thickness) scaled by ``share.scale``."""
    return np.where(s.depth < 0.0, share.scale * s.depth, s.depth)


def _segment_sizes(s: Surface, share: GapShare = GapShare()) -> np.ndarray:
    """The size share of each segment of ``s`` in a variable gap (m, Radioss GAP_M_L):
    ``share.size`` x a shell's shortest side; inf (none) for a solid's face."""
    return np.where(s.depth < 0.0, share.size * s.edge, np.inf)


def _node_gaps(nodes: np.ndarray, surfaces: list[Surface],
               share: GapShare = GapShare()) -> tuple[np.ndarray, np.ndarray]:  # fmt: skip
    """Each surface node's thickness share of a variable gap (m, Radioss GAP_S): half the
    thickness of the thickest shell at it (0 at a solid's) x ``share.scale``; and its size
    share (m, GAP_S_L): ``share.size`` x the shortest side of the shells at it (inf at a
    solid's)."""
    out, size = np.zeros(len(nodes)), np.full(len(nodes), np.inf)
    for s in surfaces:
        half = np.repeat(np.maximum(-s.depth, 0.0), 4)
        side = np.repeat(_segment_sizes(s, share), 4)
        ids = s.segments.ravel()
        rows = np.searchsorted(nodes, ids[ids >= 0])
        np.maximum.at(out, rows, half[ids >= 0])
        np.minimum.at(size, rows, side[ids >= 0])
    return share.scale * out, size
