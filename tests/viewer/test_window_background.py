"""Idle frames draw no window-sized background quad: WindowBg is transparent (ImGui skips a
rect whose alpha is 0) and the window's clear takes the color that quad blended to over it."""

from __future__ import annotations

import pytest
from imgui_bundle import hello_imgui, imgui

from shadelab.ui.app import WINDOW_BG, clear_with_window_bg


def test_window_bg_moves_into_the_clear_color():
    context = imgui.create_context()
    try:
        style = imgui.get_style()
        style.set_color_(imgui.Col_.window_bg, imgui.ImVec4(0.2, 0.4, 0.6, 0.75))
        params = hello_imgui.RunnerParams()
        params.imgui_window_params.background_color = WINDOW_BG
        clear_with_window_bg(params)
        bg = style.color_(imgui.Col_.window_bg)
        assert (bg.x, bg.y, bg.z, bg.w) == pytest.approx((0.2, 0.4, 0.6, 0.0))
        clear = params.imgui_window_params.background_color
        under = WINDOW_BG.x
        assert (clear.x, clear.y, clear.z, clear.w) == pytest.approx(
            tuple(c * 0.75 + under * 0.25 for c in (0.2, 0.4, 0.6)) + (1.0,))
        clear_with_window_bg(params)    # again (a theme change without a new color): no-op
        again = params.imgui_window_params.background_color
        assert (again.x, again.y, again.z) == pytest.approx((clear.x, clear.y, clear.z))
    finally:
        imgui.destroy_context(context)
