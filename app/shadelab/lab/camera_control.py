"""Camera control: what a mouse drag or a wheel notch does to the :class:`Camera`.

Pure numpy beside the camera model (:mod:`shadelab.scene.camera`): no GL, no GUI. The viewer
(:mod:`shadelab.ui.app`) turns ImGui mouse input into these calls.
"""

from __future__ import annotations

import math

import numpy as np

from shadelab.scene.camera import tan_half_fov_y
from shadelab.scene.model import Camera

ORBIT_SPEED = 0.008        # radians per pixel dragged, when no window height is given
ORBIT_HALF_TURN = math.pi  # a drag across the viewport's height turns this much
ZOOM_STEP = 0.9            # eye-target distance factor per wheel notch
CLICK_SLOP = 3.0           # pixels a click may move and still probe


def orbit(camera: Camera, dx: float, dy: float, height: int = 0) -> None:
    """Turn the eye around the target: dx about the up axis, dy over the top. With the
    viewport's ``height``, a drag across it turns ORBIT_HALF_TURN (180 degrees)."""
    speed = ORBIT_HALF_TURN / height if height > 0 else ORBIT_SPEED
    eye, target = np.asarray(camera.eye, float), np.asarray(camera.target, float)
    up = np.asarray(camera.up, float) / np.linalg.norm(camera.up)
    offset = eye - target
    radius = np.linalg.norm(offset)
    d = offset / radius
    right = np.cross(up, d)
    right = right / max(np.linalg.norm(right), 1e-12)
    forward = np.cross(right, up)
    elevation = math.asin(max(-1.0, min(1.0, float(np.dot(d, up)))))
    azimuth = math.atan2(float(np.dot(d, right)), float(np.dot(d, forward)))
    azimuth -= dx * speed
    elevation = max(-1.5, min(1.5, elevation + dy * speed))
    new_d = (math.cos(elevation) * (math.cos(azimuth) * forward + math.sin(azimuth) * right)
             + math.sin(elevation) * up)
    camera.eye = tuple(float(c) for c in target + radius * new_d)


def pan(camera: Camera, dx: float, dy: float, height: int, width: int = 0) -> None:
    """Slide eye and target together so the scene follows the mouse (``width``, when known,
    lets a viewport narrower than the camera's fit aspect widen the field of view)."""
    eye, target = np.asarray(camera.eye, float), np.asarray(camera.target, float)
    forward = target - eye
    distance = np.linalg.norm(forward)
    forward /= distance
    right = np.cross(forward, camera.up)
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    per_pixel = 2.0 * distance * tan_half_fov_y(camera, width / max(height, 1)) / max(height, 1)
    shift = (-dx * right + dy * up) * per_pixel
    camera.eye = tuple(float(c) for c in eye + shift)
    camera.target = tuple(float(c) for c in target + shift)


def zoom(camera: Camera, notches: float) -> None:
    """Scale the eye-target distance by ZOOM_STEP per notch (never closer than 2 x near)."""
    eye, target = np.asarray(camera.eye, float), np.asarray(camera.target, float)
    offset = (eye - target) * (ZOOM_STEP ** notches)
    if np.linalg.norm(offset) > camera.near * 2.0:
        camera.eye = tuple(float(c) for c in target + offset)


def drag(camera: Camera, dx: float, dy: float, rotate: bool, orbit_height: int,
         pan_height: int, pan_width: int = 0) -> None:
    """A mouse drag: orbit with the left button (``rotate``), else pan."""
    if rotate:
        orbit(camera, dx, dy, orbit_height)
    else:
        pan(camera, dx, dy, pan_height, pan_width)


class PointerDrag:
    """One press of a pointer over the viewport: a click (probe) or a drag (orbit / pan).

    A touch panel or an interactive whiteboard sends a press with no move before it: the
    pointer's new position and the press reach ImGui in one frame, whose mouse delta is the
    jump from the last position, and that jump orbited the camera wildly instead of probing.
    So motion counts from where the press landed, never from where the pointer was before
    it. A press becomes a drag once it has moved more than CLICK_SLOP pixels in all; only
    then do its moves turn the camera.
    """

    def __init__(self) -> None:
        self.last: tuple[float, float] | None = None
        self.travel = 0.0

    def press(self, pos: tuple[float, float]) -> None:
        self.last, self.travel = (float(pos[0]), float(pos[1])), 0.0

    def move(self, pos: tuple[float, float]) -> tuple[float, float]:
        """The motion to apply to the camera this frame ((0, 0) while still a click)."""
        if self.last is None:
            self.press(pos)
        dx, dy = float(pos[0]) - self.last[0], float(pos[1]) - self.last[1]
        self.last = (float(pos[0]), float(pos[1]))
        self.travel += abs(dx) + abs(dy)
        return (dx, dy) if self.travel > CLICK_SLOP else (0.0, 0.0)

    @property
    def is_click(self) -> bool:
        return self.travel <= CLICK_SLOP
