"""Odometry for any wheeled robot (papers 002 and 003, thesis (3.15) and ch. 7): encoders to trajectory."""
