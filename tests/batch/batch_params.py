"""The calibration parameters of the batch tests and their true values (shared by conftest and the tests)."""

PARAMS = ["left.r", "right.r", ("left.l", "right.l")]
TRUE_P = [0.01, -0.005, 0.02]
