"""Dynamics of wheeled robots with tyre friction (thesis ch. 7): traction models, mass properties, the Lagrange
model (7.2) for any described robot and its simulator. See ``docs/dynamics.md``."""
