"""Analysis benchmarks (thesis ch. 5-6): condition-number and singularity maps over 10^6 steering configurations.

Target (issue): both maps over 1,000,000 configurations in under 2 s. The peer is the obvious numpy code, one
configuration at a time: the slip matrix (3.22), its null space by SVD, the joint rates per admissible twist and
``np.linalg.cond`` (resp. the rank of the non-assigned columns, 6.12). It is timed on a subset and scaled to the
full count, so the ratio is per-configuration throughput.
"""

from __future__ import annotations

import numpy as np

from wmrkit import catalog
from wmrkit.analysis.isotropy import condition_map, default_joints
from wmrkit.analysis.singularity import singularity_distance
from wmrkit.kinematics.linalg import matrix_rank

from ._harness import Result, best_time

ROBOT = "thesis-steer-castor"  # type 3: m = 2, three steering angles (one steerable wheel, two castors)


def _loop_condition(robot, beta: np.ndarray, length: float) -> None:
    joints = [robot.velocity_index(n) for n in default_joints(robot)]
    for b in beta:
        a = robot.constraint_matrix(b)
        basis = np.linalg.svd(a)[2][-2:].T  # null space (6.7), m = 2
        twists = basis[:3] * [[1.0], [1.0], [length]]
        q, _ = np.linalg.qr(twists)
        np.linalg.cond(basis[joints] @ np.linalg.pinv(twists) @ q)


def _loop_singular(robot, beta: np.ndarray, assigned: tuple[str, ...]) -> None:
    cols = [robot.velocity_index(n) for n in assigned]
    for b in beta:
        a = robot.constraint_matrix(b)
        free = [j for j in range(a.shape[-1]) if j not in cols]
        _ = matrix_rank(a[:, free]) < len(free)


def run(quick: bool) -> list[Result]:
    """Condition and singularity maps of a type-3 robot over 1e6 configurations (1e5 quick) vs a numpy loop."""
    n, n_peer = (100_000, 2_000) if quick else (1_000_000, 10_000)
    robot = catalog.load(ROBOT)
    beta = np.random.default_rng(0).uniform(-np.pi, np.pi, (n, len(robot.steer_names)))
    length = 0.3
    assigned = ("o1.spin", "c2.steer")
    condition_map(robot, beta[:10], length=length)  # warm the caches
    results = []
    ours = best_time(lambda: condition_map(robot, beta, length=length))
    peer_s = best_time(lambda: _loop_condition(robot, beta[:n_peer], length), repeat=1) * n / n_peer
    results.append(Result("condition-number map (5.28), type 3", n, ours, "numpy loop", peer_s, "< 2 s"))
    ours = best_time(lambda: singularity_distance(robot, beta, assigned))
    peer_s = best_time(lambda: _loop_singular(robot, beta[:n_peer], assigned), repeat=1) * n / n_peer
    results.append(Result("singularity map (6.12)/(6.17), type 3", n, ours, "numpy loop", peer_s, "< 2 s"))
    return results
