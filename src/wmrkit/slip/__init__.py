"""Slip (thesis §7.4-7.5): the three slip models MQE, MCD and WLS for any robot, the velocity Kalman filters FK1
and FK2, slip-aware odometry, calibration of slip weights and the forklift study. See ``docs/slip.md``.

Modules: :mod:`.weights` (friction coefficients, WLS odometry model), :mod:`.models` (MQE, MCD, WLS, normal
loads), :mod:`.kalman` (FK1/FK2), :mod:`.estimators` (``odometry --method``), :mod:`.metrics` (J, J_k),
:mod:`.calibration`, :mod:`.synthetic`, :mod:`.skid`, :mod:`.study`.
"""

from .kalman import KalmanNoise, fk1_noise, fk2_noise, kalman_filter, kalman_model, kalman_odometry
from .metrics import closure_error, j_closure, j_model
from .models import LinearFriction, SlipSolution, mcd, mqe, normal_loads, tyre_friction, wls
from .weights import SlipWeights, wls_model

__all__ = [
    "KalmanNoise",
    "LinearFriction",
    "SlipSolution",
    "SlipWeights",
    "closure_error",
    "fk1_noise",
    "fk2_noise",
    "j_closure",
    "j_model",
    "kalman_filter",
    "kalman_model",
    "kalman_odometry",
    "mcd",
    "mqe",
    "normal_loads",
    "tyre_friction",
    "wls",
    "wls_model",
]
