"""The dynamics kernels are compiled once each for the arguments the library gives them: numba compiles a kernel
again for every new argument type, a constant flag (``Literal[bool](True)``) and a tuple of another length included,
and the first run of ``wmrkit simulate`` compiled the tyre forces three times (the step's flag, the records'
constant False, the re-linearisation's constant True) and the normal loads twice (the model's pack before and after
its last entries)."""

from __future__ import annotations

import numba
import numpy as np
from dynamics_robots import castor_robot

from wmrkit._jit import runtime_value
from wmrkit.dynamics import _kernels
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.simulate import Inputs, simulate


def test_the_model_and_a_run_that_relinearises_call_the_loads_for_one_signature():
    # called from Python, loaded from the disk cache or compiled, every signature the library gives is counted
    model = DynamicModel.of(castor_robot())
    inputs = Inputs.torques_only(model, [0.0], {"left.spin": [20.0], "right.spin": [20.0]})
    sim = simulate(model, inputs, 0.01, record_step=0.005)  # its first step is re-linearised at the grip
    model.normal_loads(), model.contact_forces(None, np.concatenate([sim.twist[-1], sim.joint_rates[-1]]))
    assert len(_kernels.normal_loads.signatures) == 1
    assert len(_kernels.contact_forces.signatures) == 1


def test_a_flag_given_as_a_constant_and_as_a_variable_compiles_its_kernel_once():
    # as the tyre forces (_kernels._contacts) are given their Jacobian flag by the step, the records and the
    # re-linearisation; numba compiles the kernels of a cached caller only when the caller is compiled, so this
    # checks the mechanism on kernels of its own
    def add_one_if(x, flag):
        return x + 1.0 if flag else x

    once, twice = numba.njit(add_one_if), numba.njit(add_one_if)

    @numba.njit
    def callers(x, flag):
        return once(x, runtime_value(True)) + once(x, flag) + twice(x, True) + twice(x, flag)

    assert callers(1.0, False) == 6.0
    assert (len(once.signatures), len(twice.signatures)) == (1, 2)


def test_the_step_loop_calls_its_solve_and_its_records_and_no_kernel_has_a_c_callable_wrapper():
    # docs/limits.md, "First run on a machine": each inlined copy is compiled anew in the step loop (the solve had
    # two call sites, a record's row two), and numba's C-callable wrapper of the loop's tuples was as large as the loop
    from wmrkit.dynamics import _integrate

    for kernel in (_kernels.solve_in_place, _integrate._row):
        assert kernel.targetoptions["inline"] == "never"
    for kernel in (_integrate.run_semi_implicit, _integrate.run_semi_implicit_linked, _integrate.assembled,
                   _kernels.solve_in_place, _kernels._contacts):
        assert kernel.targetoptions["no_cfunc_wrapper"] is True
