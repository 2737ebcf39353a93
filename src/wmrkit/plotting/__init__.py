"""Drawings: a robot seen from above (:func:`draw_robot`, :func:`save_robot_figure`)."""

from .files import PlotError
from .robot import draw_robot, save_robot_figure

__all__ = ["PlotError", "draw_robot", "save_robot_figure"]
