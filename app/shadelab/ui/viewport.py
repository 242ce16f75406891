"""The viewer's GL side: scene passes into float targets, overlays, and the display pass.

Works on any moderngl context (the viewer's window, or a headless one in tests). Every pane
is a float RenderTarget (linear radiance) plus an RGBA8 texture that imgui shows.
"""

from __future__ import annotations

from dataclasses import dataclass

import moderngl
import numpy as np

from shadelab.gl.programs import load_program, set_uniform
from shadelab.gl.target import RenderTarget
from shadelab.raster.renderer import Renderer, View
from shadelab.scene.camera import gl_matrix
from shadelab.scene.model import Scene

LINE_DEPTH_BIAS = 2e-4   # clip-space z pulled toward the eye for wireframe and glyphs


@dataclass
class Pane:
    """One rendered view: float radiance, its display texture and the last camera."""

    target: RenderTarget
    display: moderngl.Texture
    display_fbo: moderngl.Framebuffer
    view: View | None = None
    samples_asked: int = 1
    # present's settings for this pane ((exposure, tone map, clipping)) while ``display`` does
    # not hold them yet: the last display pass went straight to the window
    # (Viewport.present_to_window); read_display draws the texture first
    display_pending: tuple | None = None
    shown: tuple | None = None   # (exposure, tone map, clipping) of its last display pass

    @property
    def size(self) -> tuple[int, int]:
        return self.target.size

    def release(self) -> None:
        self.display_fbo.release()
        self.display.release()
        self.target.release()


class Viewport:
    """Renders panes for the viewer (main view, compare views, heat map)."""

    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        self.renderer = Renderer(ctx)
        self._display_variants: dict[tuple, tuple] = {}  # (mode, tonemap, clip): program, vao
        self.panes: dict[str, Pane] = {}
        self.images: dict[str, moderngl.Texture] = {}  # CPU images (offline results)
        self._anchor = ctx.simple_framebuffer((1, 1))
        self.line_width = 1.0  # overlay lines, pixels of the target (> 1: drawn as quads)
        # the overlay programs (program, buffer, vertex array) by name, made when first drawn:
        # most first frames draw no overlay, and each compile is a few ms of the start
        self._overlays: dict[str, tuple] = {}

    def _overlay_pass(self, name: str, layout: str, *attributes: str) -> tuple:
        """(program, buffer, vertex array) of the overlay program ``name`` (shaders/name.*),
        made on first use: thin lines ("lines") or lines drawn as quads ("thick_lines")."""
        made = self._overlays.get(name)
        if made is None:
            program = load_program(self.ctx, name)
            buffer = self.ctx.buffer(reserve=1 << 20, dynamic=True)
            made = self._overlays[name] = (program, buffer, self.ctx.vertex_array(
                program, [(buffer, layout, *attributes)]))
        return made

    def restore(self) -> None:
        """Bind the window's framebuffer again (imgui draws there), or a 1x1 anchor headless.

        moderngl re-binds "the previous framebuffer" after creating one; it must never be a
        framebuffer we have deleted, so one that outlives every pane is bound before releases.
        """
        (self.ctx.screen or self._anchor).use()

    # ------------------------------------------------------------ panes
    def pane(self, key: str, size: tuple[int, int], samples: int = 1) -> Pane:
        """The pane ``key`` at ``size`` with ``samples`` MSAA samples (re-made when either
        changes; ``samples`` beyond the GL's limit get the limit, see ``pane.target.samples``)."""
        size = (max(int(size[0]), 1), max(int(size[1]), 1))
        pane = self.panes.get(key)
        if pane is not None and pane.size == size and pane.samples_asked == samples:
            return pane
        if pane is not None:
            self.restore()
            pane.release()
        target = RenderTarget(self.ctx, size, samples)
        target.color.filter = (moderngl.NEAREST, moderngl.NEAREST)
        display = self.ctx.texture(size, 4, dtype="f1")
        display.filter = (moderngl.LINEAR, moderngl.LINEAR)  # upscaled at render scale < 1
        pane = Pane(target, display, self.ctx.framebuffer([display]), samples_asked=samples)
        self.panes[key] = pane
        return pane

    def draw_scene(self, key: str, scene: Scene, size: tuple[int, int], shading: str,
                   specular: str, samples: int = 1, terms_off: int = 0) -> Pane:
        """PASS 1-2 (the Renderer): the scene into the pane's float target (``samples``: MSAA,
        resolved when the pane is presented or read; ``terms_off``: the equation's terms
        switched off, shadelab.shading.codes.TERM_BITS)."""
        pane = self.pane(key, size, samples)
        pane.view = self.renderer.render(scene, pane.target, shading, specular, terms_off)
        return pane

    def draw_colored_triangles(self, pane: Pane, scene: Scene, soup: np.ndarray) -> None:
        """Per-vertex radiance triangles (a radiosity solution), Gouraud-interpolated."""
        from shadelab.geometry.mesh import scene_meshes
        from shadelab.raster.renderer import make_view

        pane.view = make_view(scene, pane.size, scene_meshes(scene))
        pane.target.clear(scene.render.background)
        self.draw_lines(pane, soup, 1.0, depth_test=True, mode=moderngl.TRIANGLES, bias=0.0)

    def draw_lines(self, pane: Pane, lines: np.ndarray, exposure: float,
                   depth_test: bool = True, mode: int = moderngl.LINES,
                   bias: float = LINE_DEPTH_BIAS) -> None:
        """Overlay colored segments (wireframe, glyphs, arrows) onto the float target."""
        if len(lines) == 0 or pane.view is None:
            return
        if mode == moderngl.LINES and self.line_width > 1.0:
            self._draw_thick(pane, lines, exposure, depth_test, bias)
            return
        data = np.ascontiguousarray(lines, dtype=np.float32).tobytes()
        program, buffer, vao = self._overlay_pass("lines", "3f 3f", "in_position", "in_color")
        if len(data) > buffer.size:
            buffer.orphan(len(data) * 2)
        buffer.write(data)
        pane.target.use()
        self.ctx.enable_only(moderngl.DEPTH_TEST if depth_test else moderngl.NOTHING)
        set_uniform(program, "u_clip_from_world", gl_matrix(pane.view.clip_from_world))
        set_uniform(program, "u_depth_bias", bias if depth_test else 0.0)
        set_uniform(program, "u_scale", 1.0 / max(exposure, 1e-12))
        vao.render(mode, vertices=len(lines))

    def _draw_thick(self, pane: Pane, lines: np.ndarray, exposure: float, depth_test: bool,
                    bias: float) -> None:
        """Segments as quads ``self.line_width`` pixels wide (see shaders/thick_lines.vert)."""
        data = np.ascontiguousarray(thick_line_vertices(lines), dtype=np.float32).tobytes()
        program, buffer, vao = self._overlay_pass("thick_lines", "3f 3f 3f 1f", "in_position",
                                                  "in_other", "in_color", "in_side")
        if len(data) > buffer.size:
            buffer.orphan(len(data) * 2)
        buffer.write(data)
        pane.target.use()
        self.ctx.enable_only(moderngl.DEPTH_TEST if depth_test else moderngl.NOTHING)
        set_uniform(program, "u_clip_from_world", gl_matrix(pane.view.clip_from_world))
        set_uniform(program, "u_depth_bias", bias if depth_test else 0.0)
        set_uniform(program, "u_scale", 1.0 / max(exposure, 1e-12))
        set_uniform(program, "u_viewport", tuple(float(c) for c in pane.size))
        set_uniform(program, "u_width", float(self.line_width))
        vao.render(moderngl.TRIANGLES, vertices=len(lines) // 2 * 6)

    def present(self, pane: Pane, exposure: float, source: Pane | None = None,
                other: Pane | None = None, diff_scale: float = 0.05, tonemap: str = "clamp",
                clipping: bool = False) -> moderngl.Texture:
        """Display pass into ``pane``'s RGBA8 texture: exposure, tone map (clamp | reinhard),
        sRGB of ``source`` (default the pane itself), or the |source - other| heat map when
        ``other`` is given; ``clipping`` stripes the pixels the clamp cuts."""
        pane.display_pending = None
        if other is None and source is None:
            pane.shown = (exposure, tonemap, clipping)
        pane.display_fbo.use()
        self._display_pass(pane, exposure, source, other, diff_scale, tonemap, clipping)
        return pane.display

    def present_to_window(self, pane: Pane, exposure: float, tonemap: str, clipping: bool,
                          rect: tuple[int, int, int, int]) -> None:
        """The display pass of ``pane`` drawn straight into the window's framebuffer at
        ``rect`` (x, y from the bottom left, width, height: the pane's own size), the bytes
        :meth:`present` writes into the texture; imgui then draws nothing there, a
        window-sized textured quad less per frame (issue 25). The texture is left as it was
        (``display_pending``) until something reads it (:meth:`read_display`)."""
        pane.display_pending = pane.shown = (exposure, tonemap, clipping)
        screen = self.ctx.screen
        screen.use()
        before = screen.viewport
        screen.viewport = rect
        try:
            self._display_pass(pane, exposure, None, None, 0.05, tonemap, clipping)
        finally:
            screen.viewport = before

    def display_texture(self, pane: Pane) -> moderngl.Texture:
        """``pane``'s display texture, drawn first if the last display pass went to the window
        only (``display_pending``)."""
        if pane.display_pending is not None:
            exposure, tonemap, clipping = pane.display_pending
            self.present(pane, exposure, tonemap=tonemap, clipping=clipping)
        return pane.display

    def blit_to_window(self, pane: Pane, rect: tuple[int, int, int, int]) -> None:
        """``pane``'s display texture copied into the window's framebuffer at ``rect`` (an idle
        frame: the image did not change). After a window pass the texture is drawn first,
        once; then each idle frame is a copy, cheaper than a display pass or imgui's quad."""
        from shadelab.gl import lite

        source = self.display_texture(pane)
        w, h = source.size
        x, y = rect[0], rect[1]
        _ = self.ctx.error
        lite.glBindFramebuffer(lite.GL_READ_FRAMEBUFFER, pane.display_fbo.glo)
        lite.glBindFramebuffer(lite.GL_DRAW_FRAMEBUFFER, 0)
        lite.glBlitFramebuffer(0, 0, w, h, x, y, x + w, y + h, lite.GL_COLOR_BUFFER_BIT,
                               lite.GL_NEAREST)
        self.restore()   # moderngl's record of the bound framebuffer stays true

    def _display_pass(self, pane: Pane, exposure: float, source: Pane | None,
                      other: Pane | None, diff_scale: float, tonemap: str,
                      clipping: bool) -> None:
        """The display program over the bound framebuffer's viewport."""
        source = source or pane
        source.target.resolve()
        if other is not None:
            other.target.resolve()
        self.ctx.enable_only(moderngl.NOTHING)
        source.target.color.use(0)
        (other or source).target.color.use(1)
        program, vao = self.display_variant(1 if other is not None else 0,
                                            1 if tonemap == "reinhard" else 0, int(clipping))
        set_uniform(program, "t_image", 0)
        set_uniform(program, "t_other", 1)
        set_uniform(program, "u_exposure", float(exposure))
        set_uniform(program, "u_diff_scale", float(diff_scale))
        vao.render(moderngl.TRIANGLES, vertices=3)
        self.restore()

    def display_variant(self, mode: int, tonemap: int, clipping: int):
        """The display program compiled for one (mode, tone map, clipping) and its VAO (made on
        first use): no masked branch runs for the others (shaders/display.frag)."""
        key = (mode, tonemap, clipping)
        variant = self._display_variants.get(key)
        if variant is None:
            program = load_program(self.ctx, "display", {"DISPLAY_MODE": mode,
                                                         "DISPLAY_TONEMAP": tonemap,
                                                         "DISPLAY_CLIPPING": clipping})
            variant = self._display_variants[key] = (program,
                                                     self.ctx.vertex_array(program, []))
        return variant

    # ------------------------------------------------------------ read back
    def read_pixel(self, key: str, pixel: tuple[int, int]) -> np.ndarray:
        """Linear RGB the scene pass drew at (x, y), row 0 at the top (reads one pixel)."""
        value = self.panes[key].target.read_pixel(*pixel)
        self.restore()
        return value.astype(np.float64)

    def read_linear(self, key: str) -> np.ndarray:
        return self.panes[key].target.read()

    def read_display(self, key: str) -> np.ndarray:
        """What the pane shows: (H, W, 3) uint8 sRGB, row 0 at the top."""
        pane = self.panes[key]
        w, h = pane.size
        data = np.frombuffer(self.display_texture(pane).read(), dtype=np.uint8).reshape(h, w, 4)
        return np.ascontiguousarray(data[::-1, :, :3])

    def upload_image(self, key: str, image_srgb8: np.ndarray) -> moderngl.Texture:
        """A texture holding an (H, W, 3) uint8 image, or (H, W, 4) with its alpha (row 0 at
        the top), for imgui.image."""
        h, w = image_srgb8.shape[:2]
        if image_srgb8.shape[2] == 4 and image_srgb8.flags.c_contiguous:
            rgba = image_srgb8
        else:
            rgba = np.empty((h, w, 4), np.uint8)
            rgba[..., :3], rgba[..., 3] = image_srgb8[..., :3], 255
        tex = self.images.get(key)
        if tex is None or tex.size != (w, h):
            if tex is not None:
                tex.release()
            tex = self.ctx.texture((w, h), 4, dtype="f1")
            tex.filter = (moderngl.NEAREST, moderngl.NEAREST)
            self.images[key] = tex
        tex.write(memoryview(rgba).cast("B"))  # row 0 first: imgui's uv puts it on top
        return tex

    def release(self) -> None:
        self.restore()
        for pane in self.panes.values():
            pane.release()
        self.panes.clear()
        for tex in self.images.values():
            tex.release()
        for program, buffer, vao in self._overlays.values():
            vao.release()
            buffer.release()
            program.release()
        self._overlays.clear()
        for program, vao in self._display_variants.values():
            vao.release()
            program.release()
        self._display_variants.clear()
        self.renderer.release()
        (self.ctx.screen or self.ctx.detect_framebuffer(0)).use()
        self._anchor.release()


def thick_line_vertices(lines: np.ndarray) -> np.ndarray:
    """(2N, 6) segment ends (position, color) -> (6N, 10) quad corners: position, other end,
    color, side (+1 / -1), two triangles per segment."""
    ends = np.asarray(lines, dtype=np.float32).reshape(-1, 2, 6)
    p0, p1, c0, c1 = ends[:, 0, :3], ends[:, 1, :3], ends[:, 0, 3:], ends[:, 1, 3:]
    n = len(ends)

    def corner(p, q, c, side):
        return np.concatenate([p, q, c, np.full((n, 1), side, np.float32)], axis=1)

    a, b = corner(p0, p1, c0, 1.0), corner(p0, p1, c0, -1.0)
    c, d = corner(p1, p0, c1, 1.0), corner(p1, p0, c1, -1.0)
    return np.stack([a, b, c, a, c, d], axis=1).reshape(-1, 10)
