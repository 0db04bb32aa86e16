"""What self-contact costs: its share of the step on the crushed tube, and the search per node.

    python bench/contact.py [--out bench/contact.md] [--quick]
    mpirun -n 2 python bench/contact.py --tube-only --out bench/contact.md   (appends)

1. **Tube**: the square shell tube of ``demos/tube_crush.toml`` (self-contact ``self =
   true``, J2 at 5 points, 100 kg at 10 m/s) at about 10,000 and 100,000 quadrilaterals
   (``--tube-cells``; the element size from the cell count). Every step of the run is
   timed (processor time, each rank's, the slowest rank's sums): the whole step, the
   internal force, and the interface's ``accelerate`` (gather, bucket sort when due, near
   lists when due, the compiled passes over them, the nodal step, the forces added), with
   the sort (with the near lists made at it) and the gather apart.
   The contact's share is taken over the steps at or after ``--fold-time`` (folds in
   contact; the number of nodes in contact is given), as the median over blocks of
   ``--block`` steps and over all of them, and over the first millisecond (no fold yet).
   From ``--large-from`` cells (50,000: the 100k run) the tube is scaled up around and along (by
   sqrt(cells / 10,000): 158 x 158 x 474 mm) at the 10k tube's element size of 1.73 mm, and
   runs ``--large-end`` (0.15 ms, before any fold): the 6 ms of the crush would be some
   50,000 steps of 100,000 shells, more than a shared rank can give it (the demo's tube
   in 0.55 mm shells, finer than its 1.5 mm thickness, runs with ``--large-from`` above
   its cells: its variable gap is capped by the shells' size, :mod:`rwall_fem.contact`).
2. **Search**: the bucket sort of ``kernels/contact.c`` as the interface calls it
   (``ContactInterface._sort``: one self-contact pass, all nodes secondary, each node's
   own segments excluded) on a pleated sheet of n x n quadrilaterals of 1 mm
   (``sheet``: folds 0 to 2.4 mm apart, as in a crushed tube), gap 0.75 mm, margin 1 mm,
   from 10k to 1M nodes; ns per node, median of ``--repeats`` sorts; and one pass of the contact
   forces (``contact_forces``: the closest points among the candidates) per node. Writes
   ``docs/contact_search.png`` (matplotlib) with ``--figure``.

Writes Markdown (``--out``, included in docs/performance.md) and a JSON beside it.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import statistics
import tempfile
import time
from pathlib import Path
from types import SimpleNamespace

import numpy as np
from mpi4py import MPI

from rwall_fem import build_simulation, parse_scene
from rwall_fem.contact.interface import ContactInterface, Pass
from rwall_fem.scene.read import read_toml

comm = MPI.COMM_WORLD
HERE = Path(__file__).resolve().parent
SCENE = HERE.parent / "demos" / "tube_crush.toml"
PERIMETER, LENGTH = 0.2, 0.15  # m: the tube's mid-surface, 4 x 50 mm around, 150 mm long
BASE_CELLS = 10_000  # the larger tubes keep this one's element size (1.73 mm)
LEG, PLEAT = 10, 1.2e-3  # the search's sheet: elements per leg, lean of a leg (m)


def load_average() -> str:
    return " ".join(f"{x:.1f}" for x in os.getloadavg())


# -- 1. The tube ------------------------------------------------------------------------


def tube_scene(cells: int, end: float, large: bool):
    """The demo's tube at ``cells`` quadrilaterals: its own size at the element size that
    gives them, or (``large``) scaled up around and along at the element size of
    BASE_CELLS (the shells no smaller than their thickness), the press's mass with it."""
    raw = read_toml(SCENE)
    mesh = raw["mesh"]
    scale = math.sqrt(cells / BASE_CELLS) if large else 1.0
    base = BASE_CELLS if large else cells
    mesh["element_size"] = math.sqrt(PERIMETER * LENGTH / base)
    mesh["width"], mesh["length"] = mesh["width"] * scale, mesh["length"] * scale
    raw["wall"][1]["point"][2] = raw["wall"][1]["point"][2] * scale
    raw["wall"][1]["motion"]["mass"] *= scale**2
    raw["run"]["end_time"] = end
    raw["output"] |= {"frames": 0, "plot": False}
    return parse_scene(raw, source=f"bench:contact tube {cells}")


class StepClock:
    """Processor time (s) of each step and of its phases: wraps the loop's calls."""

    PHASES = ("internal", "contact", "sort", "gather")

    def __init__(self, sim):
        self.sim, self.starts, self.times = sim, [], []
        self.phase = {k: [] for k in self.PHASES}
        self.contacts: list[int] = []
        self._now = dict.fromkeys(self.PHASES, 0.0)
        contact = sim.contacts[0]
        internal = sim.internal
        self._wrap(internal, "accelerate", "internal", first=True)
        self._wrap(contact, "accelerate", "contact")
        self._wrap(contact, "_sort", "sort")
        self._wrap(contact, "_read", "gather")
        self._wrap(contact, "_read_ghosts", "gather")
        self.contact = contact

    def _wrap(self, owner, attribute, name, first=False):
        call = getattr(owner, attribute)
        clock = time.process_time

        def timed(*args, **kwargs):
            t0 = clock()
            if first:  # a step starts: close the previous one
                self._close(t0)
            try:
                return call(*args, **kwargs)
            finally:
                self._now[name] += clock() - t0

        setattr(owner, attribute, timed)

    def _close(self, t0):
        if self.starts:
            for k in self.PHASES:
                self.phase[k].append(self._now[k])
            self.contacts.append(self.contact.contacts)
        self._now = dict.fromkeys(self.PHASES, 0.0)
        self.starts.append(t0)
        self.times.append(self.sim.state.t)

    def arrays(self):
        """Per finished step: its time t (s), processor seconds, phases, contacts."""
        n = len(self.starts) - 1
        step = np.diff(np.array(self.starts))
        return (np.array(self.times[:n]), step,
                {k: np.array(v[:n]) for k, v in self.phase.items()},
                np.array(self.contacts[:n]))  # fmt: skip


def slowest(values: np.ndarray) -> np.ndarray:
    """Each step's largest value over the ranks."""
    out = np.empty_like(values)
    comm.Allreduce(values, out, op=MPI.MAX)
    return out


def deck_scene(path: Path):
    from rwall_fem.radioss import load_deck

    scene = load_deck(path, (), comm, report=[])
    return scene


def tube(sc, fold_time: float, block: int) -> dict:
    """The timed run of scene ``sc``: its books and the contact's shares (see the top)."""
    folder = comm.bcast(tempfile.mkdtemp(prefix="rwall-bench-contact-") if comm.rank == 0
                        else None)  # fmt: skip
    sim = build_simulation(sc, comm, Path(folder) / "run", limits=False)
    clock = StepClock(sim)
    sim.run()
    t, step, phase, contacts = clock.arrays()
    n = comm.allreduce(len(t), op=MPI.MIN)
    t, step, contacts = t[:n], slowest(step[:n]), contacts[:n]
    phase = {k: slowest(v[:n]) for k, v in phase.items()}
    summary = sim.history.summary

    def window(mask) -> dict:
        idx = np.flatnonzero(mask)
        blocks = [idx[i:i + block] for i in range(0, len(idx) - block + 1, block)] or [idx]
        shares = [phase["contact"][b].sum() / step[b].sum() for b in blocks if len(b)]
        return {
            "steps": int(len(idx)),
            "from_ms": float(t[idx[0]] * 1e3) if len(idx) else None,
            "to_ms": float(t[idx[-1]] * 1e3) if len(idx) else None,
            "ms_per_step": float(step[idx].mean() * 1e3) if len(idx) else None,
            "share": float(phase["contact"][idx].sum() / step[idx].sum()) if len(idx) else None,
            "share_median_of_blocks": float(statistics.median(shares)) if shares else None,
            "blocks": len(blocks),
            **{f"{k}_share": float(v[idx].sum() / step[idx].sum()) for k, v in phase.items()},
            "contacts_mean": float(contacts[idx].mean()) if len(idx) else None,
            "contacts_max": int(contacts[idx].max(initial=0)),
        }

    contact = sim.contacts[0]
    return {
        "cells": sim.info.get("cells"),
        "surface_nodes": contact.size,
        "element_size_mm": sc.mesh.element_size * 1e3 if sc.mesh.element_size else None,
        "width_mm": sc.mesh.width * 1e3 if sc.mesh.width else None,
        "status": sim.status,
        "end_ms": sc.run.end_time * 1e3,
        "loop_seconds": sim.wall_seconds,
        "steps": summary["steps"],
        "sorts": contact.sorts,
        "balance": summary.get("energy_balance"),
        "all": window(t >= 0.0),
        "early": window(t < 1e-3),
        "folds": window(t >= fold_time),
        "contacts_by_ms": [[float(a * 1e3), int(c)] for a, c in zip(t[::500], contacts[::500])],
    }


# -- 2. The search ----------------------------------------------------------------------


def sheet(nodes: int):
    """A pleated sheet of about ``nodes`` nodes (m x m quadrilaterals of about 1 mm), as a
    crushed tube's folds: it runs up and down in legs of LEG elements, 10 mm high, each
    leaning PLEAT along x, so that neighbouring legs meet at a fold and stand 2 PLEAT apart
    at the other end: positions (m) and quadrilaterals."""
    h = 1e-3
    m = int(round(math.sqrt(nodes))) - 1
    i, j = np.meshgrid(np.arange(m + 1), np.arange(m + 1), indexing="ij")
    leg, up = np.divmod(i.ravel(), LEG)
    rise = np.where(leg % 2 == 0, up, LEG - up) / LEG
    X = np.ascontiguousarray(np.stack([(leg + up / LEG) * PLEAT, j.ravel() * h,
                                       rise * LEG * h], axis=1))  # fmt: skip
    a = (i[:-1, :-1] * (m + 1) + j[:-1, :-1]).ravel()
    quads = np.stack([a, a + m + 1, a + m + 2, a + 1], axis=1).astype(np.int64)
    return X, quads


def search(nodes: int, repeats: int) -> dict:
    """ns per node of the interface's sort and of one contact pass, on the sheet."""
    X, quads = sheet(nodes)
    n = len(X)
    gap, margin = 0.75e-3, 1e-3
    state = SimpleNamespace(X=X, u=np.zeros_like(X), v=np.zeros_like(X),
                            mass=np.full(n, 1e-3), a=np.zeros_like(X), dt_previous=1e-7)  # fmt: skip
    ps = Pass(np.arange(n, dtype=np.int64), quads, np.full(len(quads), 1e8),
              np.full(len(quads), -0.5 * gap))  # fmt: skip
    interface = ContactInterface("bench", np.arange(n, dtype=np.int64), [ps], gap=gap,
                                 friction=0.0, alpha=1.0, margin=margin, state=state,
                                 comm=MPI.COMM_SELF, owned_global=np.arange(n))  # fmt: skip
    interface._read(state)
    interface._sort()  # the candidate arrays grown to size
    sorts, passes = [], []
    lib, arguments = interface.lib, interface._passes[0]
    for _ in range(repeats):
        t0 = time.process_time()
        interface._sort()
        sorts.append(time.process_time() - t0)
        arguments = interface._passes[0]
        t0 = time.process_time()
        lib.contact_forces(n, *arguments)
        passes.append(time.process_time() - t0)
    return {
        "nodes": n,
        "segments": len(quads),
        "candidates": int(interface.passes[0].offsets[-1]),
        "sort_ns_per_node": statistics.median(sorts) / n * 1e9,
        "pass_ns_per_node": statistics.median(passes) / n * 1e9,
        "sort_all": sorts,
        "pass_all": passes,
    }


def figure(rows: list[dict], path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    nodes = [r["nodes"] for r in rows]
    fig, ax = plt.subplots(figsize=(6, 3.6))
    ax.semilogx(nodes, [r["sort_ns_per_node"] for r in rows], "o-",
                label="bucket sort (contact_sort, as the interface calls it)")  # fmt: skip
    ax.semilogx(nodes, [r["pass_ns_per_node"] for r in rows], "s-",
                label="one pass of the forces (closest points)")  # fmt: skip
    ax.set_xlabel("surface nodes (all secondary, self-contact)")
    ax.set_ylabel("ns per node")
    ax.set_ylim(bottom=0)
    ax.grid(True, which="both", alpha=0.3)
    ax.legend(fontsize=8)
    ax.set_title("Contact search on a pleated sheet of quadrilaterals", fontsize=10)
    fig.tight_layout()
    fig.savefig(path, dpi=110)
    plt.close(fig)


# -- Report ---------------------------------------------------------------------------------


def tube_lines(results: dict, before: str, after: str) -> list[str]:
    ranks = f"{comm.size} rank{'s' if comm.size > 1 else ''}"
    lines = [f"### Tube crush with self-contact, {ranks}", "",
             f"Load average before {before}, after {after}; processor time per step (the "
             "slowest rank's), contact = the interface's `accelerate` (gather, sort when "
             "due, near lists when due, passes, nodal step, forces added).", "",
             "| cells | tube (mm) | steps | window | ms/step | internal force | **contact** | "
             "of it sort | of it gather | nodes in contact (mean / max) |",
             "|---:|---|---:|---|---:|---:|---:|---:|---:|---|"]  # fmt: skip
    for cells, r in results.items():
        for name, label in (("early", "first ms (no fold)"), ("folds", "folds in contact")):
            w = r[name]
            if not w["steps"]:
                continue
            lines.append(
                f"| {r['cells']:,} | {r['width_mm']:.0f} | {w['steps']:,} | {label}, "
                f"{w['from_ms']:.2f}-{w['to_ms']:.2f} ms | {w['ms_per_step']:.2f} | "
                f"{w['internal_share']:.1%} | **{w['share']:.1%}** (median of {w['blocks']} "
                f"blocks {w['share_median_of_blocks']:.1%}) | {w['sort_share']:.1%} | "
                f"{w['gather_share']:.1%} | {w['contacts_mean']:.0f} / {w['contacts_max']} |"
            )
    lines.append("")
    return lines


def deck_lines(path: Path, r: dict, before: str, after: str) -> list[str]:
    w, e = r["folds"], r["early"]
    every = r["all"]
    return [f"### The peer tube deck with self-contact ({path.name}), {comm.size} rank(s)", "",
            f"Load average before {before}, after {after}: {r['steps']:,} cycles, a loop of "
            f"{r['loop_seconds']:.1f} s (wall), {every['ms_per_step']:.2f} ms of processor "
            f"time per cycle; the contact takes **{every['share']:.1%}** of the loop "
            f"({e['share']:.1%} over the first ms, {w['share']:.1%} from "
            f"{w['from_ms']:.1f} ms on, {w['contacts_mean']:.0f} nodes in contact on average "
            f"there, {w['contacts_max']} at most); sort {every['sort_share']:.1%}, gather "
            f"{every['gather_share']:.1%}; {r['sorts']} sorts.", ""]  # fmt: skip


def main():
    p = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    p.add_argument("--out", type=Path, help="write (1 rank) or append (N ranks) Markdown")
    p.add_argument("--quick", action="store_true", help="10k tube to 2.5 ms, search to 100k")
    p.add_argument("--tube-cells", type=int, nargs="*", default=[10_000, 100_000])
    p.add_argument("--end", type=float, default=6.0e-3, help="s, at 10 m/s")
    p.add_argument("--fold-time", type=float, default=2.0e-3, help="s, at 10 m/s")
    p.add_argument("--large-from", type=int, default=50_000,
                   help="cells from which the tube is scaled up at 10k's element size")
    p.add_argument("--large-end", type=float, default=1.5e-4, help="s: the end of those")
    p.add_argument("--block", type=int, default=500)
    p.add_argument("--search-nodes", type=int, nargs="*",
                   default=[10_000, 30_000, 100_000, 300_000, 1_000_000])  # fmt: skip
    p.add_argument("--repeats", type=int, default=5)
    p.add_argument("--tube-only", action="store_true")
    p.add_argument("--deck", type=Path, help="time this deck's run instead (the peer tube "
                   "deck: gen_shell.py tube --h 2.5 --contact; its folds from --fold-time)")
    p.add_argument("--search-only", action="store_true")
    p.add_argument("--figure", type=Path, default=HERE.parent / "docs" / "contact_search.png")
    a = p.parse_args()
    if a.quick:
        a.tube_cells, a.end = [10_000], 3.0e-3
        a.search_nodes = [10_000, 30_000, 100_000]
    record = {"ranks": comm.size}
    lines = []
    if not a.search_only and not a.deck:
        before = load_average()
        results = {}
        for cells in a.tube_cells:
            large = cells >= a.large_from
            sc = tube_scene(cells, a.large_end if large else a.end, large)
            results[cells] = tube(sc, a.fold_time, a.block)
            if comm.rank == 0:
                print(json.dumps({k: v for k, v in results[cells].items()
                                  if k != "contacts_by_ms"}), flush=True)  # fmt: skip
        record["tube"] = results
        lines += tube_lines(results, before, load_average())
    if a.deck:
        before = load_average()
        r = tube(deck_scene(a.deck), a.fold_time, a.block)
        record["deck"] = r
        if comm.rank == 0:
            print(json.dumps({k: v for k, v in r.items() if k != "contacts_by_ms"}), flush=True)
        lines += deck_lines(a.deck, r, before, load_average())
    if not a.tube_only and not a.deck and comm.size == 1:
        before = load_average()
        rows = [search(n, a.repeats) for n in a.search_nodes]
        record["search"] = rows
        figure(rows, a.figure)
        lines += ["### Search per node, 1 rank", "",
                  f"Load average before {before}, after {load_average()}; medians of "
                  f"{a.repeats} calls, processor time; the figure: `{a.figure.name}`.", "",
                  "| nodes | segments | candidates | sort, ns/node | forces pass, ns/node |",
                  "|---:|---:|---:|---:|---:|"]  # fmt: skip
        for r in rows:
            lines.append(f"| {r['nodes']:,} | {r['segments']:,} | {r['candidates']:,} | "
                         f"{r['sort_ns_per_node']:.0f} | {r['pass_ns_per_node']:.0f} |")  # fmt: skip
        lines.append("")
    if comm.rank:
        return
    text = "\n".join(lines)
    print(text)
    if a.out:
        data = a.out.with_suffix(".json")
        if comm.size == 1:
            title = ("## Contact\n\n`python bench/contact.py --out bench/contact.md` then "
                     "`mpirun -n 2 python bench/contact.py --tube-only --out "
                     "bench/contact.md` (the docstring says how).\n\n")  # fmt: skip
            a.out.write_text(title + text)
            data.write_text(json.dumps([record], indent=1))
        else:
            with a.out.open("a") as out:
                out.write("\n" + text)
            old = json.loads(data.read_text()) if data.exists() else []
            data.write_text(json.dumps(old + [record], indent=1))


if __name__ == "__main__":
    main()
