"""The whole-fleet checks of the runs judged by their residual ratios (:func:`wmrkit.batch.consistency.judge`).

Several runs that disagree hide each other from their ratios (each inflates the others' fit's error), so the runs are
also judged as a whole: those whose own fit has :data:`~wmrkit.batch.homogeneity.MIN_DOF` (27) degrees of freedom or
more by Cochran's homogeneity (:func:`~wmrkit.batch.homogeneity.fleet_warning`), the others (references of 4 to 10
poses) by the fleet likelihood ratio of their whitened motions' errors
(:func:`~wmrkit.batch.likelihood.few_pose_warning`, designed for few degrees of freedom, its level exact for any
number of them). Before, those were not judged as a whole and nothing said so: 3 runs of a left radius +5 % among
6 four-pose runs, 'inconsistent' false, no warning, 'not_judged' null. Fewer than 3 such runs are named as not so
judged (:data:`UNCOVERED`); 1 or 2 runs of 27 degrees of freedom or more join the others in the likelihood ratio
(before, they too were left out unsaid).
"""

from __future__ import annotations

from collections.abc import Sequence

import numpy as np

from ..odometry.calibration import CalibrationProblem
from .homogeneity import MIN_DOF, fleet_warning
from .likelihood import few_pose_warning

#: Runs judged by their ratios that no whole-fleet check covers ({runs}): fewer than 3 runs of fewer than
#: :data:`~wmrkit.batch.homogeneity.MIN_DOF` degrees of freedom of their own fit.
UNCOVERED = ("{runs}: not checked as a whole with the other runs (each whole-fleet check needs 3 runs or more: the "
             f"fleet homogeneity runs of {MIN_DOF} degrees of freedom of their own fit or more, the fleet likelihood "
             "ratio the others): each is still checked against the others on its own")

#: Runs scored as closed paths whose own fits leave fewer than :data:`~wmrkit.batch.likelihood.MIN_OWN_DOF` degrees of
#: freedom ({runs}: closed paths, references of 2 poses): no whole-fleet check can judge them (each needs a run's own
#: noise), so three runs or more that disagree hide each other from their scores (one is named by its score, two by
#: the pair score). Before, nothing said so ('not_judged' null).
NO_OWN_NOISE = ("{runs}: not checked as a whole (closed paths or references of 2 poses: a run's own fit leaves no "
                "noise to judge it by): three runs or more that disagree may hide each other from their scores; one "
                "run or a pair that disagrees is looked for")


def whole_fleet(problem: CalibrationProblem, p: np.ndarray, jac: np.ndarray, res: np.ndarray, which: Sequence[int],
                floors: Sequence[float], logs: Sequence[str], named: bool) -> tuple[tuple[str, ...], str | None]:
    """The warnings of the whole-fleet checks of the runs `which` (those with residual ratios; `jac`, `res`: the
    fleet fit's at parameters `p`; `floors`: least RSS root of each run's own fit [m]; `named`: a ratio named one
    run) and what they leave out or do not make (joined), or ``None`` (module docstring)."""
    warning, unmade, covered = fleet_warning(problem, jac, res, which, floors, logs, named)
    rest = [k for k in which if len(covered) < 3 or k not in covered]  # 1 or 2 such runs: with the others
    said, aside = (None, UNCOVERED.format(runs=", ".join(logs[k] for k in rest)) if rest else None)
    if len(rest) >= 3:
        said, aside = few_pose_warning(problem, p, jac, res, rest, floors, logs, int(named))
    warnings = tuple(w for w in (warning, said) if w)
    return warnings, "; ".join(x for x in (unmade, aside) if x) or None
