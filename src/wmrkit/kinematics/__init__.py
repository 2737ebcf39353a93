"""No-slip kinematic models (thesis ch. 4) and per-wheel inverse kinematics (§8.4)."""
