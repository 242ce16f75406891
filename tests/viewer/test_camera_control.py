"""Camera control (shadelab.lab.camera_control) against closed forms: orbit turns pi per
viewport height, pan moves 2 d tan(fov/2) per viewport height, zoom scales by 0.9 per notch."""

from __future__ import annotations

import math

import numpy as np
import pytest

from shadelab.lab.camera_control import CLICK_SLOP, ORBIT_SPEED, ZOOM_STEP, drag, orbit, pan, zoom
from shadelab.scene.model import Camera


def _camera() -> Camera:
    return Camera(eye=(0.0, 0.0, 5.0), target=(0.0, 0.0, 0.0), up=(0.0, 1.0, 0.0), fov_y=60.0,
                  near=0.1)


@pytest.mark.parametrize("pixels", [25.0, 100.0, 333.0])
def test_orbit_turns_pi_per_viewport_height_about_up(pixels):
    cam, height = _camera(), 400
    orbit(cam, pixels, 0.0, height)
    angle = -pixels * math.pi / height  # dx to the right turns the eye to the left
    expected = 5.0 * np.array([math.sin(angle), 0.0, math.cos(angle)])
    np.testing.assert_allclose(cam.eye, expected, atol=1e-12)
    assert cam.target == (0.0, 0.0, 0.0)


def test_a_drag_across_the_height_is_a_half_turn():
    cam = _camera()
    orbit(cam, 300.0, 0.0, 300)
    np.testing.assert_allclose(cam.eye, (0.0, 0.0, -5.0), atol=1e-12)


def test_orbit_over_the_top_raises_the_elevation_and_clamps_it():
    cam = _camera()
    orbit(cam, 0.0, 50.0, 400)
    elevation = 50.0 * math.pi / 400
    np.testing.assert_allclose(cam.eye, 5.0 * np.array([0.0, math.sin(elevation),
                                                        math.cos(elevation)]), atol=1e-12)
    orbit(cam, 0.0, 10_000.0, 400)  # never over the pole
    assert math.asin(cam.eye[1] / 5.0) == pytest.approx(1.5)


def test_orbit_without_a_height_uses_the_fixed_speed():
    cam = _camera()
    orbit(cam, 10.0, 0.0)
    angle = -10.0 * ORBIT_SPEED
    np.testing.assert_allclose(cam.eye, (5.0 * math.sin(angle), 0.0, 5.0 * math.cos(angle)),
                               atol=1e-12)


def test_pan_moves_eye_and_target_by_the_view_height_per_viewport_height():
    cam, height = _camera(), 500
    pan(cam, 50.0, 20.0, height)
    per_pixel = 2.0 * 5.0 * math.tan(math.radians(30.0)) / height
    # looking down -z with y up: right is +x; the scene follows the mouse
    shift = np.array([-50.0 * per_pixel, 20.0 * per_pixel, 0.0])
    np.testing.assert_allclose(cam.target, shift, atol=1e-12)
    np.testing.assert_allclose(cam.eye, np.array([0.0, 0.0, 5.0]) + shift, atol=1e-12)


def test_pan_in_a_viewport_narrower_than_the_fit_aspect_follows_the_wider_view():
    cam, height, width = _camera(), 500, 250          # aspect 0.5 < fit_aspect 1: fov widened
    pan(cam, 50.0, 0.0, height, width)
    per_pixel = 2.0 * 5.0 * math.tan(math.radians(30.0)) * (1.0 / 0.5) / height
    np.testing.assert_allclose(cam.target, (-50.0 * per_pixel, 0.0, 0.0), atol=1e-12)


@pytest.mark.parametrize("notches", [1.0, -2.0, 3.5])
def test_zoom_scales_the_distance_by_the_step_per_notch(notches):
    cam = _camera()
    zoom(cam, notches)
    np.testing.assert_allclose(cam.eye, (0.0, 0.0, 5.0 * ZOOM_STEP ** notches), atol=1e-12)


def test_zoom_stops_at_twice_the_near_plane():
    cam = _camera()
    zoom(cam, 100.0)  # 5 * 0.9**100 < 0.2: refused
    assert cam.eye == (0.0, 0.0, 5.0)


def test_drag_orbits_with_the_left_button_else_pans_by_the_pane_height():
    a, b = _camera(), _camera()
    drag(a, 30.0, 0.0, True, 300, 150)
    orbit(b, 30.0, 0.0, 300)
    assert a.eye == b.eye
    a, b = _camera(), _camera()
    drag(a, 30.0, 10.0, False, 300, 150)
    pan(b, 30.0, 10.0, 150)
    assert (a.eye, a.target) == (b.eye, b.target)
    assert CLICK_SLOP > 0


def test_a_press_at_a_new_position_probes_instead_of_orbiting():
    """A touch panel or whiteboard sends a press far from the last pointer position with no
    move in between: motion counts from the press, so it is a click (before: the jump of the
    frame's mouse delta, hundreds of pixels, orbited the camera)."""
    from shadelab.lab.camera_control import CLICK_SLOP, PointerDrag

    pointer = PointerDrag()
    pointer.press((640.0, 420.0))               # a press that lands where the pointer is
    assert pointer.move((640.0, 420.0)) == (0.0, 0.0) and pointer.is_click
    # the frame's mouse delta would have been the jump from the last position (10, 10)
    assert pointer.move((641.0, 421.0)) == (0.0, 0.0) and pointer.is_click  # within the slop
    # a real drag: once past CLICK_SLOP every move turns the camera, by its own motion
    assert pointer.move((650.0, 421.0)) == (9.0, 0.0) and not pointer.is_click
    assert pointer.move((650.0, 431.0)) == (0.0, 10.0)
    assert pointer.travel == pytest.approx(2.0 + 9.0 + 10.0) and CLICK_SLOP < 9.0
    # a drag keeps its big moves once it is one
    assert pointer.move((730.0, 431.0)) == (80.0, 0.0)
