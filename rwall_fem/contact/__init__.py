"""Contact between the parts of the body and of a part with itself (Radioss /INTER/TYPE7).

:func:`build_contacts` turns a scene's ``[[contact]]`` tables into
:class:`~rwall_fem.contact.interface.ContactInterface` forces of the step: the main
segments are the boundary faces of the main parts (:mod:`~rwall_fem.contact.surface`),
the secondary nodes the nodes of the secondary parts' boundary faces; a symmetric
interface also runs the other way; a self-contact (``self = true``) runs the main parts'
nodes against their own faces, each node kept off its own faces and their neighbours.
"""

from __future__ import annotations

import numpy as np

from rwall_fem.contact.interface import ContactInterface, Pass
from rwall_fem.contact.surface import Surface, part_surface

__all__ = ["build_contacts"]


def build_contacts(scene, solid, state) -> list[ContactInterface]:
    """The contact interfaces of ``scene`` on the body of ``solid`` (``build._Solid``),
    acting on ``state``; :class:`~rwall_fem.scene.SceneError` (one line, on every rank)
    for a part the body does not have, a side without faces, or a gap not smaller than a
    part."""
    from rwall_fem.scene import SceneError
    from rwall_fem.scene.keys import did_you_mean
    from rwall_fem.walls.constraint import filter_alpha

    body, comm = solid.elastic, solid.comm
    failing = any(getattr(p.material, "failure", None) for p in scene.body_parts)
    if failing or scene.run.dt_min_action == "erode":
        raise SceneError(
            f"{scene.source}: contact[0]: contact in a body whose cells may erode (a failure "
            "criterion, or run.dt_min_action = 'erode') is not supported yet: the faces of "
            "eroded cells would stay in the contact surface; drop [[contact]] or the erosion"
        )
    names = [part.name for part in solid.parts]
    owned = solid.V.dofmap.index_map.local_to_global(np.arange(solid.owned, dtype=np.int32))
    surfaces: dict[str, Surface] = {}
    interfaces = []
    for i, spec in enumerate(scene.contacts):
        where = f"{scene.source}: contact[{i}]"

        def side(key: str, parts: tuple[str, ...]) -> Surface:
            for name in parts:
                if name not in names:
                    raise SceneError(
                        f"{where}.{key}: the body has no part {name!r}"
                        f"{did_you_mean(name, names)}; its parts: {', '.join(names)}"
                    )
            for name in parts:
                if name not in surfaces:
                    surfaces[name] = part_surface(body, names.index(name), comm)
            found = [surfaces[name] for name in dict.fromkeys(parts)]
            total = found[0]
            for more in found[1:]:
                total = total + more
            if not len(total.segments):
                raise SceneError(f"{where}.{key}: the parts {', '.join(parts)} have no "
                                 "boundary face")  # fmt: skip
            return total

        if spec.single_surface:
            main = side("main", spec.main or tuple(names))
            sides = [(main, main, True)]
        else:
            main, secondary = side("main", spec.main), side("secondary", spec.secondary)
            sides = [(secondary, main, False)] + ([(main, secondary, False)] if spec.symmetric else [])
        nodes = np.unique(np.concatenate([s.nodes for pair in sides for s in pair[:2]]))
        edge = float(min(s.edge.min() for pair in sides for s in pair[:2]))
        gap = spec.gap if spec.gap is not None else 0.1 * edge
        passes = [
            Pass(
                np.searchsorted(nodes, sec.nodes).astype(np.int64),
                np.where(seg.segments >= 0, np.searchsorted(nodes, seg.segments), -1),
                spec.stiffness_scale * seg.stiffness,
                seg.depth.copy(),
                exclude,
            )
            for sec, seg, exclude in sides
        ]
        interface = ContactInterface(
            f"contact[{i}]", nodes, passes, gap=gap, friction=spec.friction,
            alpha=filter_alpha(spec.friction_filter, state.dt), margin=edge, state=state,
            comm=comm, owned_global=owned, damping=spec.damping,
        )  # fmt: skip
        interface.start(state)
        for key, parts in (("main", spec.main or tuple(names)), ("secondary", spec.secondary)):
            for name in parts:
                ids = np.searchsorted(nodes, surfaces[name].nodes)
                x = interface.x[ids]
                smallest = float((x.max(axis=0) - x.min(axis=0)).min())
                if gap >= smallest:
                    raise SceneError(
                        f"{where}.gap: {gap:g} m is not smaller than part {name!r} "
                        f"({smallest:g} m across at its thinnest): the gap must be a small "
                        "fraction of the parts (default 0.1 x the shortest edge)"
                    )
        interfaces.append(interface)
    return interfaces
