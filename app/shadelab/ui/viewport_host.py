"""What a panel or viewport layout may ask of the viewer's viewport: :class:`ViewportHost`.

:class:`shadelab.ui.app.Viewer` implements it; :mod:`shadelab.ui.compare_view` and
:mod:`shadelab.ui.presenter` take a ``ViewportHost``, never the Viewer itself, and call
nothing private of it. Types only: no imgui and no GL module, not even for type checking
(only the GL side names the GL classes: ``viewport`` is a :class:`shadelab.ui.viewport.Viewport`,
``gpu`` a :class:`shadelab.ui.gpu_side.GpuSide`).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, Protocol

if TYPE_CHECKING:
    from shadelab.lab.state import AppState


class ViewportHost(Protocol):
    """The viewport window's owner, as the layouts drawn into it see it."""

    @property
    def state(self) -> AppState:
        """The panels' state (read and written by the layouts too)."""

    @property
    def viewport(self) -> Any:
        """The GL side's panes (a Viewport): draw the scene into them, present them."""

    @property
    def gpu(self) -> Any:
        """The GL side serving the panels' GPU requests (``state.gpu``; a GpuSide)."""

    def image_with_input(self, texture, size: tuple[int, int]) -> tuple[float, float] | None:
        """Show ``texture`` at ``size`` with the viewport's mouse handling (orbit, pan, zoom,
        gizmo); returns the clicked point in the image, or None."""

    def unchanged(self, size: tuple[int, int]) -> bool:
        """True when the last image is still right (the frame key did not change)."""

    def samples(self) -> int:
        """MSAA samples of the scene pass."""

    def draw_viewport_window(self) -> None:
        """The viewport window's content (the scene, compare grid or pipeline image)."""

    def report_error(self, message: str) -> None:
        """Show an error raised inside a panel on the status line."""
