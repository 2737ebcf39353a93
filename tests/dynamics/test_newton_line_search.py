"""The semi-implicit step's Newton iterations search along their step (``_newton.line_search``): near standstill a
tyre's force is steep across zero slip and flat beyond, and an iteration linearised where the tyre slides jumped
across the zero, to the other side of the grip, and back. The swerve robot of test_steering_servo on its 8 m/s turn
(centre of mass 0.5 m high, the front wheels spinning up from rest with 20 N on them) ended 24 of its first 300 steps
at 1 ms unconverged (all within the first 70), after the 8 iterations of ``GRIP_ITERATIONS``."""

from __future__ import annotations

from test_steering_servo import _swerve

from wmrkit._jit import _python_namespace
from wmrkit.dynamics import _integrate
from wmrkit.dynamics._newton import GRIP_ITERATIONS
from wmrkit.dynamics.model import DynamicModel
from wmrkit.dynamics.programs import path_program
from wmrkit.dynamics.simulate import Stepper


def test_every_step_of_the_swerve_turn_s_start_converges():
    """The step's loop as plain Python (the compiled kernels' source), counting each step's Newton iterations and
    whether its last one converged: the first 30 steps at 1 ms (12 of the 24) each converge, in 3 to 5."""
    model = DynamicModel.of(_swerve(com_height=0.5))
    stepper = Stepper(model, step=1e-3, allow_lift_off=True)
    stepper.advance(path_program(model, "turn", speed=8.0)[0], 0.0)  # its inputs, compiled; no step yet
    ns = _python_namespace(vars(_integrate), {})
    relinearise, assemble, steps = ns["relinearise"], ns["assemble"], []

    def counted_relinearise(*args):
        steps[-1][0] += 1
        steps[-1][1] = relinearise(*args)
        return steps[-1][1]

    def counted_assemble(*args):  # once at each step's start, in the loop (the step is written there)
        steps.append([0, False])
        assemble(*args)

    ns["relinearise"], ns["assemble"] = counted_relinearise, counted_assemble
    ns["run_semi_implicit"](stepper.state, 0, 1e-3, 30, 1 << 62, stepper.jac_every, 0, stepper._acc, model.pack,
                            stepper._inputs, stepper._w, stepper._rec, 0)
    assert len(steps) == 30 and sum(n > 0 for n, _ in steps) >= 29  # the premise: the loads move at every step
    assert [k for k, (n, done) in enumerate(steps) if n > 0 and not done] == []
    assert max(n for n, _ in steps) < GRIP_ITERATIONS
