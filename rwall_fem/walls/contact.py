"""The per-node passes of a wall's contact, compiled (``kernels/wall.c``).

:class:`ContactPasses` holds, for one wall, the shape as the C code reads it and the
arrays the passes fill, sized for the wall's near set: :meth:`~ContactPasses.find` lists
the nodes in contact at a step, :meth:`~ContactPasses.impulses` gives their impulses for
a wall velocity, :meth:`~ContactPasses.apply` adds them to the accelerations, and
:meth:`~ContactPasses.work` sums the work of impulses, :meth:`~ContactPasses.coupling` the
equations of a main-node wall's velocity; :meth:`~ContactPasses.clearance` and
:meth:`~ContactPasses.largest` select and keep the near set. The arithmetic is NumPy's,
operation for operation (``kernels/wall.c``), so that the results are those of the NumPy
code that ``walls/constraint.py`` had before.
"""

from __future__ import annotations

import numpy as np

from rwall_fem.kernels import load

__all__ = ["SLIDES", "ContactPasses"]

KINDS = ("plane", "parallelogram", "cylinder", "sphere")  # the order of kernels/wall.c
SLIDES = ("free", "tied", "friction")  # likewise


def _pointer(ffi, array: np.ndarray, kind: str = "double[]"):
    if not array.flags.c_contiguous:
        raise ValueError("the wall's passes need C-contiguous arrays")
    return ffi.from_buffer(kind, array)


def _shape_record(ffi, shape):
    """The ``wall_shape`` of ``shape`` (a shape of :mod:`rwall_fem.walls.shapes`)."""
    record = ffi.new("wall_shape *")
    record.kind = KINDS.index(shape.kind)
    record.point = shape.point.tolist()
    if shape.kind in ("plane", "parallelogram"):
        record.normal = shape.normal.tolist()
    if shape.kind == "parallelogram":
        record.dual = shape.dual.ravel().tolist()
        record.widths = shape.widths.tolist()
    if shape.kind == "cylinder":
        record.axis = shape.axis.tolist()
    if shape.kind in ("cylinder", "sphere"):
        record.radius = shape.radius
        record.fallback = np.broadcast_to(shape.fallback, 3).tolist()
    return record


class ContactPasses:
    """The compiled passes of one wall of ``shape`` over the nodes of its near set, on the
    arrays of ``state`` (a :class:`~rwall_fem.solver.State`, whose arrays never move).

    After :meth:`find` returned k, the first k rows of :attr:`hits` (positions in the near
    set), :attr:`nodes`, :attr:`mass` (kg), :attr:`normals`, :attr:`predicted` (v*, m/s),
    :attr:`previous` (v^{n-1/2}, m/s) and :attr:`target` (m/s) describe the nodes in
    contact; after :meth:`impulses`, :attr:`normal` and :attr:`tangential` (N s) and
    :attr:`slip` their impulses. They are views of arrays the next :meth:`find` overwrites.
    """

    def __init__(self, shape, state):
        self.ffi, self.lib = load()
        self.state = state
        self._shape = _shape_record(self.ffi, shape)
        self._state = [_pointer(self.ffi, x) for x in (state.X, state.u, state.v, state.a)]
        self._mass = _pointer(self.ffi, state.mass)
        self._v, self._a = self._state[2:]
        # offset, next offset and velocity of the wall (m, m, m/s), the sums of apply, the
        # main node's predicted velocity (m/s)
        self._vectors = np.zeros(3 * 3 + 9 + 3)
        self._vectors_pointer = _pointer(self.ffi, self._vectors)
        # the sums of coupling; then the main node's matrix, right side and velocity; works
        self._coupling = np.zeros(12 + 9 + 3 + 3 + 2)
        self._coupling_pointer = _pointer(self.ffi, self._coupling)
        self._coupling_sums = self._coupling[:12]
        self._clearance = np.zeros(0)
        self._rows = {}  # pointers to the arrays of some calls, by their use (_rows_pointer)
        self._reserve(0)

    def _reserve(self, n: int) -> None:
        """Room for ``n`` nodes in contact (only ever grows: the near set changes often)."""
        capacity = max(n, 16)
        if getattr(self, "capacity", -1) >= capacity:
            return
        self.capacity = capacity
        self.hits = np.zeros(capacity, dtype=np.int64)
        self.nodes = np.zeros(capacity, dtype=np.int64)
        self.mass = np.zeros(capacity)
        self.target = np.zeros(capacity)
        self.slip = np.zeros(capacity, dtype=bool)
        vectors = ("normals", "predicted", "previous", "normal", "tangential", "_scratch")
        for name in vectors:
            setattr(self, name, np.zeros((capacity, 3)))
        p = self.ffi.from_buffer
        self._pointers = {
            name: p("double[]", getattr(self, name)) for name in (*vectors, "mass", "target")
        }
        self._pointers |= {
            "hits": p("int64_t[]", self.hits),
            "nodes": p("int64_t[]", self.nodes),
            "slip": p("uint8_t[]", self.slip),
        }

    def _rows_pointer(self, use: str, array: np.ndarray, kind: str = "int64_t[]"):
        """The pointer to ``array`` (a node list by default), kept for the next call of the
        same ``use`` while it is handed the same array (a near set lives for many steps; the
        array is kept with it, so that no other can take its place)."""
        kept = self._rows.get(use)
        if kept is None or kept[0] is not array:
            kept = self._rows[use] = (array, _pointer(self.ffi, array, kind))
        return kept[1]

    def clearance(self, nodes: np.ndarray, offset) -> tuple[np.ndarray, float]:
        """The clearance (m) of ``nodes`` (node indices, int64) from the wall at ``offset``
        (m), as the shape's ``clearance``, and the largest absolute coordinate of their
        positions (m; NaN if one is NaN)."""
        if len(self._clearance) != len(nodes):
            self._clearance = np.zeros(len(nodes))
        self._vectors[0:3] = offset
        largest = self.lib.wall_clearance(
            len(nodes), _pointer(self.ffi, nodes, "int64_t[]"), self._state[0], self._state[1],
            self._shape, self._vectors_pointer, _pointer(self.ffi, self._clearance),
        )  # fmt: skip
        return self._clearance, largest

    def largest(self, nodes: np.ndarray, span: tuple[int, int] | None = None) -> tuple:
        """The largest absolute component of the velocities (m/s) and of the accelerations
        (m/s^2) of ``nodes`` (node indices, int64; NaN values left out), in one pass; with
        ``span`` (first, end), ``nodes`` are the range first, ..., end - 1 (a contiguous
        pass)."""
        sums = self._vectors_pointer + 9
        if span is not None:
            first, end = span
            self.lib.largest_range(3 * (end - first), self._v + 3 * first, self._a + 3 * first,
                                   sums)  # fmt: skip
        else:
            rows = self._rows_pointer("largest", nodes)
            self.lib.largest_components(len(nodes), rows, self._v, self._a, sums)
        speed, acceleration = self._vectors[9:11].tolist()
        return speed, acceleration

    def find(self, near: np.ndarray, dt_v: float, dt: float, offset, wall_next, velocity) -> int:
        """Test the nodes ``near`` (node indices, int64) against the wall at ``offset`` now
        and ``wall_next`` after the step (m), moving at ``velocity`` (m/s) over it; returns
        how many are in contact (listed in the arrays)."""
        self._reserve(len(near))
        vectors, q = self._vectors, self._pointers
        vectors[0:3], vectors[3:6], vectors[6:9] = offset, wall_next, velocity
        w = self._vectors_pointer
        X, u, v, a = self._state
        return self.lib.wall_find(
            len(near), self._rows_pointer("near", near), X, u, v, a, self._mass, dt_v,
            dt, self._shape, w, w + 3, w + 6, q["hits"], q["nodes"], q["mass"], q["normals"],
            q["predicted"], q["previous"], q["target"],
        )  # fmt: skip

    def impulses(self, k: int, slide: str, friction: float, alpha: float, velocity, kept=None):
        """The impulses (N s) of the k nodes in contact for a wall moving at ``velocity``
        (m/s): :attr:`normal`, :attr:`tangential` (not for ``slide`` "free") and
        :attr:`slip`; ``kept`` (k, 3): the friction filter's previous impulses."""
        self._vectors[6:9] = velocity
        q = self._pointers
        filtered = self.ffi.NULL if kept is None else _pointer(self.ffi, kept)
        self.lib.wall_impulses(
            k, SLIDES.index(slide), friction, alpha, q["mass"], q["normals"], q["predicted"],
            self._vectors_pointer + 6, q["target"], filtered, q["normal"], q["tangential"],
            q["slip"],
        )  # fmt: skip

    def apply(self, k: int, tangential: bool, dt_v: float, before) -> tuple:
        """Add the impulses of the k nodes in contact (the normal ones, and the tangential
        if ``tangential``) to their accelerations, impulse / (m dt_v); returns the sums
        over them of the normal, tangential and whole impulses (N s; rows of a (3, 3)
        view) and the sums of impulse . (v^{n-1/2} - ``before``) (N m/s; normal and
        tangential, 0 without: the works' first halves at the wall's velocity before)."""
        q, w = self._pointers, self._vectors_pointer
        t = q["tangential"] if tangential else self.ffi.NULL
        self._vectors[6:9] = before
        self.lib.wall_apply(
            k, q["nodes"], q["mass"], q["normal"], t, dt_v, self._a, w + 9, q["previous"],
            w + 6, q["_scratch"], self._coupling_pointer + 27,
        )  # fmt: skip
        normal_work, tangential_work = self._coupling[27:29].tolist()
        return self._vectors[9:18].reshape(3, 3), (normal_work, tangential_work)

    def coupling(self, k: int, tied: bool, slip: bool = False) -> np.ndarray:
        """The sums over the k nodes in contact of the equations of a main-node wall's
        velocity V, (M + sum m_i P_i) V = M V* + sum m_i (P_i v*_i - n_i b_i) - extra: the
        9 values of sum m_i P_i (rows of 3), then the 3 of the right side's sum, kg and
        N s (a view the next call overwrites). P_i is the identity for a tied node (all
        are when ``tied``), n_i n_i^T for another; with ``slip``, the nodes of :attr:`slip`
        slip (the others are tied) and bring their :attr:`tangential` impulses as extra."""
        q, null = self._pointers, self.ffi.NULL
        self.lib.wall_coupling(
            k, tied, q["slip"] if slip else null, q["mass"], q["normals"], q["predicted"],
            q["target"], q["tangential"] if slip else null, self._coupling_pointer,
        )  # fmt: skip
        return self._coupling_sums

    def coupled_velocity(self, k: int, tied: bool, slip: bool, mass: float, predicted, held):
        """:meth:`coupling` then :meth:`velocity` in one call, on one rank (its sums are the
        totals)."""
        q, c, null = self._pointers, self._coupling_pointer, self.ffi.NULL
        self._vectors[18:21] = predicted
        p, held = self._vectors_pointer + 18, self._rows_pointer("held", held, "uint8_t[]")
        if self.lib.wall_coupled(
            k, tied, q["slip"] if slip else null, q["mass"], q["normals"], q["predicted"],
            q["target"], q["tangential"] if slip else null, mass, p, held, c,
        ):  # fmt: skip
            return self._coupling[24:27].copy()
        return np.linalg.solve(self._coupling[12:21].reshape(3, 3), self._coupling[21:24])

    def velocity(self, total: np.ndarray, mass: float, predicted: np.ndarray, held) -> np.ndarray:
        """The main node's velocity (m/s) over the step from the sums ``total`` of
        :meth:`coupling` over the ranks: (M I + total) V = M V* + total's right side, V_j =
        V*_j for the components ``held`` (a uint8 mask of 3; kg, m/s). A diagonal system
        (all nodes tied) is divided (what LAPACK's solve does to it, to the bit), another
        solved by NumPy."""
        c, q = self._coupling, self._coupling_pointer
        if total is not self._coupling_sums:
            c[:12] = total
        self._vectors[18:21] = predicted
        p, held = self._vectors_pointer + 18, self._rows_pointer("held", held, "uint8_t[]")
        if self.lib.wall_velocity(q, mass, p, held, q + 12, q + 21, q + 24):
            return c[24:27].copy()
        return np.linalg.solve(c[12:21].reshape(3, 3), c[21:24])

    def work(self, normal, tangential, velocity, nodes) -> tuple[float, float]:
        """sum impulse . (v - ``velocity``) (N m/s) over the rows of the impulses ``normal``
        and ``tangential`` (k, 3; or None: 0), v the current velocity of the ``nodes``
        (node indices, int64), in one pass."""
        k = len(normal)
        self._reserve(k)
        self._vectors[6:9] = velocity
        q = self._pointers
        if nodes.base is self.nodes and normal.base is self.normal and (
            tangential is None or tangential.base is self.tangential
        ):  # the latest step's contacts, as find and impulses left them: pointers kept
            n, f, t = q["nodes"], q["normal"], q["tangential"]
        else:
            n, f = _pointer(self.ffi, nodes, "int64_t[]"), _pointer(self.ffi, normal)
            t = _pointer(self.ffi, tangential) if tangential is not None else None
        self.lib.wall_work(
            k, n, f, self.ffi.NULL if tangential is None else t, self._v,
            self._vectors_pointer + 6, q["_scratch"], self._coupling_pointer + 27,
        )  # fmt: skip
        normal_work, tangential_work = self._coupling[27:29].tolist()
        return normal_work, tangential_work
