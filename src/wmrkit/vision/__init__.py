"""Line following by vision (thesis §9.2): camera model, synthetic camera, line extraction, positioning,
calibration and closed-loop following. OpenCV (the 'vision' extra) is imported only when an image is processed.
See ``docs/vision.md``."""

from .calibration import Calibration, calibrate, calibrate_image
from .camera import Camera, CameraError, extrinsics, project, rotation
from .follow import LineFollowing, follow_line, line_following_twist, locate_image
from .lines import DetectedLine, extract_lines
from .positioning import LineFix, Positioning, line_position, locate_points, read_points
from .render import Scene, render

__all__ = ["Calibration", "Camera", "CameraError", "DetectedLine", "LineFix", "LineFollowing", "Positioning",
           "Scene", "calibrate", "calibrate_image", "extract_lines", "extrinsics", "follow_line",
           "line_following_twist", "line_position", "locate_image", "locate_points", "project", "read_points",
           "render", "rotation"]
