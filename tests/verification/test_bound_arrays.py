"""The compiled passes read and write NumPy arrays through raw pointers bound once: they
must act on the arrays the Python side holds now, whatever happened since they were bound.

- The acceleration pass a = -f / m of a body (solids, shells, one element force) and the
  update of a step follow the state they are handed: another state's arrays get the
  result (on a state with twice the mass, half the acceleration, to the bit), and the
  state bound before is left as it was. Bound once for good, they wrote into the first
  state's arrays, freed or not, and left the new state's untouched.
- A force whose cells were deactivated (rigid bodies) refuses to erode: its kernels would
  read the live cells from the list of the computed ones, past its end.
- After a run stopped and resumed through mass scaling, and through erosion, every pointer
  of the kernels' parameters and every pointer argument of the bound passes is the address
  of an array the objects hold now (the resumed run equals the uninterrupted one bit for
  bit: tests/verification/test_time_step.py, test_failure.py).
"""

import copy

import numpy as np
import pytest
from conftest import StopAt
from mpi4py import MPI

from rwall_fem import build_simulation, parse_scene
from rwall_fem.solver import CentralDifference, State

comm = MPI.COMM_WORLD
STEEL = {"model": "linear_elastic", "density": 7800.0, "young": 2.1e11, "poisson": 0.3}


def solid_scene() -> dict:
    return {
        "run": {"end_time": 1e-5},
        "mesh": {"shape": "bar", "size": [2e-3, 2e-3, 6e-3], "element_size": 1e-3},
        "material": dict(STEEL),
        "output": {"frames": 0, "plot": False},
    }


def shell_scene() -> dict:
    return {
        "run": {"end_time": 1e-5},
        "mesh": {"shape": "plate", "size": [0.04, 0.02, 0.002], "element_size": 0.005,
                 "cell": "quadrilateral"},  # fmt: skip
        "material": dict(STEEL),
        "output": {"frames": 0, "plot": False},
    }


def built(raw, directory=None):
    return build_simulation(parse_scene(copy.deepcopy(raw), source="test"), comm, directory)


def address(ffi, pointer) -> int:
    return int(ffi.cast("uintptr_t", ffi.cast("void *", pointer)))


def at(array) -> int:
    return 0 if array is None else array.ctypes.data


@pytest.mark.parametrize("scene", [solid_scene, shell_scene])
def test_the_acceleration_follows_the_state_it_is_handed(scene):
    sim = built(scene())
    first = sim.state
    rng = np.random.default_rng(comm.rank)
    first.u[:] = 1e-7 * rng.standard_normal(first.u.shape)  # m: loads every cell
    first.v[:] = 1e-1 * rng.standard_normal(first.v.shape)  # m/s: and the shells' rate form
    first.dt_previous = first.dt
    sim.internal.accelerate(first)
    first.dt_previous = 0.0  # from now on no increment: the same forces at every pass
    passes = [sim.internal]
    if scene is solid_scene:
        passes.append(sim.internal.elements[0])  # an element force alone
    for body in passes:
        body.accelerate(first)
        a = first.a.copy()
        assert comm.allreduce(float(np.abs(a).max(initial=0.0)), op=MPI.MAX) > 0.0
        second = State(X=first.X, mass=2.0 * first.mass, dt=first.dt, u=first.u, v=first.v)
        body.accelerate(second)
        assert np.array_equal(second.a, 0.5 * a)  # 1 / (2 m) is (1 / m) / 2 exactly
        assert np.array_equal(first.a, a)
        first.a[:] = 0.0
        body.accelerate(first)  # and back
        assert np.array_equal(first.a, a)


def test_the_update_follows_the_state_it_is_handed():
    """v^{1/2} = v^0 + dt a^0 and u^1 = u^0 + dt v^{1/2} (the first step's dt^0 is dt) on
    the state handed to the update, not on the one it was built with."""
    rng = np.random.default_rng(7)

    def state():
        s = State(X=np.zeros((5, 3)), mass=rng.uniform(1.0, 2.0, 5), dt=0.1)
        s.u[:], s.v[:], s.a[:] = rng.standard_normal((3, 5, 3))
        return s

    first, second = state(), state()
    update = CentralDifference(first)
    before = first.u.copy(), first.v.copy()
    v = second.v + 0.1 * second.a
    u = second.u + 0.1 * v
    update(second)
    assert np.array_equal(second.v, v) and np.array_equal(second.u, u)
    assert np.array_equal(first.u, before[0]) and np.array_equal(first.v, before[1])


def test_a_force_with_deactivated_cells_refuses_to_erode():
    force = built(solid_scene()).internal.elements[0]
    force.deactivate(np.arange(min(1, force.num_cells)))
    with pytest.raises(ValueError, match="deactivated cells cannot erode"):
        force.erode_below(1e-9)


def assert_bound(sim) -> None:
    """Every pointer the compiled passes of ``sim`` read is the address of an array its
    objects hold now."""
    s = sim.state
    scaling = getattr(sim.step_size, "mass_scaling", None)
    for k, force in enumerate(sim.internal.elements):
        p, ffi, e = force.params, force.ffi, force.erosion
        live = e.live if e is not None else getattr(force, "_computed", None)
        expected = {"live": at(live)}
        if e is not None:
            expected |= {"eroded": at(e.listed), "cell_work": at(e.work),
                         "velocity": at(force.v.array)}  # fmt: skip
        if scaling is not None:
            expected |= {"step_factor": at(scaling.factors[k]), "below": at(force.below),
                         "below_step": at(force.below_step)}  # fmt: skip
        if hasattr(force, "kernel"):  # shells
            expected["thickness"] = at(force.kernel.thickness)
            fields = (force.w.array, force.m.array)
            structs = (p, force.kernel.shell)
        else:
            expected |= {"length0": at(force.length0), "volume0": at(force.volume0)}
            fields, structs = (), (p,)
        for name, where in expected.items():
            struct = force.kernel.shell if name == "thickness" else p
            assert address(ffi, getattr(struct, name)) == where, name
        arrays = (force.u.array, force.v.array, force.f.array, force._energy, force.step,
                  force.cells, force.X, force.history, *fields)  # fmt: skip
        held = {at(x) for x in arrays}
        call = force._kernel
        pointers = [x for x in call.args if isinstance(x, ffi.CData) and x not in structs]
        assert {address(ffi, x) for x in pointers} <= held
        computed = e.computed if e is not None else len(live) if live is not None else None
        assert call.args[0] == (force.num_cells if computed is None else computed)
    ffi = sim.internal.elements[0].ffi
    call, body = sim.internal._acceleration, sim.internal
    bound = [body.f.array, s.inv_mass, s.a]
    if hasattr(body, "alpha"):  # shells: the rotations in the same sweep
        bound += [body.m.array, body.inv_inertia, body._free, body.alpha]
    assert [address(ffi, x) for x in call.args[1:]] == [at(x) for x in bound]
    arrays = (s.mass, s.a, s.v, s.u)
    assert [address(ffi, x) for x in sim.update._arrays[:4]] == [at(x) for x in arrays]
    assert address(ffi, sim.update._arrays[7]) == at(s.momentum_integral)
    for wall in sim.walls:
        if wall._passes is not None:
            arrays = [s.X, s.u, s.v, s.a]
            assert [address(ffi, x) for x in wall._passes._state] == [at(x) for x in arrays]
            assert address(ffi, wall._passes._mass) == at(s.mass)


def stopped_and_resumed(raw, directory, stop: int, more: int):
    """``raw`` run into ``directory`` and stopped after step ``stop``, then resumed from its
    checkpoint and stopped again ``more`` steps later: both simulations."""
    sim = built(raw, directory)
    sim.recorders.append(StopAt(stop))
    assert sim.run().startswith(f"stopped: step {stop},")
    resumed = built(raw, directory)
    resumed.checkpoints.resume(resumed)
    resumed.recorders.append(StopAt(stop + more))
    assert resumed.run().startswith(f"stopped: step {stop + more},")
    return sim, resumed


def test_the_passes_hold_the_arrays_of_a_run_resumed_through_mass_scaling(shared_dir):
    from test_time_step import crush_scene

    raw = crush_scene(dt_min=5e-8, dt_min_action="mass_scaling")
    for sim in stopped_and_resumed(raw, shared_dir, 300, 50):
        assert comm.allreduce(sim.step_size.mass_scaling.cells) > 0
        assert_bound(sim)


def test_the_passes_hold_the_arrays_of_a_run_resumed_through_erosion(shared_dir):
    from test_failure import punch_scene

    for sim in stopped_and_resumed(punch_scene(), shared_dir, 60, 20):
        assert sim.history.summary["erosion"]["eroded_cells"] > 0
        assert_bound(sim)


def test_the_passes_of_shells_hold_their_arrays(shared_dir):
    raw = shell_scene() | {"initial": {"velocity": [0.0, 0.0, -5.0]}}
    raw["run"] |= {"dt_min": 1e-9, "dt_min_action": "mass_scaling"}
    sim = built(raw, shared_dir)
    sim.recorders.append(StopAt(20))
    sim.run()
    assert_bound(sim)
