"""Stencil shadow volumes on moderngl (the GL side; geometry in shadelab/geometry/silhouette.py).

Per light: clear the stencil, draw every caster's volume with color and depth writes off and
two-sided stencil counting, then draw that light's contribution additively where the count is
zero. z-fail (Carmack's reverse) counts volume faces *behind* the visible surface (back faces
+1, front faces -1) and is robust with the eye inside a volume, given far caps at infinity
(w = 0, infinite far plane, depth clamp on). z-pass counts faces *in front* (front +1, back -1)
and breaks when the eye sits inside a volume: it is here to show that failure.

The count draws a closed caster's volume with fans for caps where the counts stay the same
(:class:`shadelab.geometry.silhouette.CountVolume`): the far cap at infinity always (it lies at
depth 1 and only its outline, the extruded silhouette, decides which pixels it covers), the
near cap on a convex caster seen from outside (the fan lies inside the caster, where no visible
point is). The lecture sphere's volume drops from 5860 triangles to 432; the volumes shown in the
teaching overlay keep their full caps.

With z-fail the count then draws each volume cut off where its rays leave the receivers' box
(:func:`shadelab.geometry.silhouette.bounded_volume`): the far ends move in from infinity to a
face of the box grown by BOUND_MARGIN of its diagonal, so the sides stop past the last receiver
instead of sweeping the screen to their vanishing point (the lecture's count: ~7 ms to ~2 ms
at 1024x672 on llvmpipe). Every point of the box keeps its count; the image is bit-identical
(tests/raster/test_lecture_fast_path.py). The volumes shown in the overlay still reach
infinity, as in the lecture's figure.

moderngl has no stencil API: stencil state goes through PyOpenGL (ARCHITECTURE.md section 4).
"""

from __future__ import annotations

from dataclasses import dataclass

import moderngl
import numpy as np

from shadelab.geometry.mesh import scene_bounds
from shadelab.geometry.silhouette import (
    BOUND_MARGIN,
    CountVolume,
    PlanarOccluder,
    ShadowVolume,
    bounded_volume,
    box_corners,
    closed_caster,
    count_volume,
    is_convex,
    open_caster_groups,
    open_volume,
    planar_occluder,
    shadow_volume,
    shadows_nothing,
    volume_sources,
)
from shadelab.gl.programs import load_program, set_uniform
from shadelab.raster.memo import memoized
from shadelab.scene.camera import gl_matrix
from shadelab.scene.model import Light, Scene
from shadelab.shading.lights import light_kind

RECENT = 64        # memoized answers kept per light and geometry set (then started again)
GEOMETRIES = 256   # memoized answers kept per mesh geometry
OFFSET_FRACTION = 1e-3  # open casters' volumes start this share of the scene's diagonal away
VOLUME_COLOR = (0.25, 0.45, 1.0, 0.18)  # translucent volumes (linear RGB, alpha)
# glPolygonOffset(factor, units) for the drawn volumes: behind the caster surface they lie on
# (factor: the slope of grazing faces at the terminator; units: 24-bit depth steps)
VOLUME_DEPTH_OFFSET = (1.0, 4.0)
SILHOUETTE_COLOR = (1.0, 0.85, 0.1, 1.0)
HEAT_LEVELS = 8  # stencil counts 1..8 get their own color; above 8 shows as 8
# kt-filtered shadows: with transparent casters the stencil splits into a 4-bit volume counter
# (mod 16) and one "inside caster j's volume" flag per transparent caster (bits 4..7)
COUNTER_MASK = 0x0F
FILTER_SLOTS = 4  # transparent casters filtered per light; further ones cast no shadow
# The stencil count draws closed casters' volumes with fans for caps where the counts are the
# same (silhouette.CountVolume); False counts with the full caps (A/B measurements, tests)
REDUCED_CAPS = True
# pixels added round ShadowVolumes.screen_rect (rasterization rules, float rounding)
SCISSOR_PAD = 2
# The count leaves out a flat opaque caster's volume where everything that volume could hold
# is hidden behind that caster from the eye (silhouette.PlanarOccluder: the lecture's back
# wall); False counts every volume (A/B measurements, tests)
HIDDEN_VOLUMES_LEFT_OUT = True
# The z-fail count draws each volume cut off where its rays leave the receivers' box
# (silhouette.bounded_volume: the same counts, the sides end past the last receiver instead of
# running across the screen to their vanishing point); False counts the volumes to infinity
BOUNDED_VOLUMES = True
# the bounded volumes' far cap lies BOUND_MARGIN of the box's diagonal beyond it: counted with
# them only while a depth step there is below 1/DEPTH_STEPS_IN_MARGIN of that (a 24-bit depth
# buffer, infinite far plane: a step at distance z is z^2 / (near 2^24))
DEPTH_STEPS_IN_MARGIN = 64


def filter_bit(slot: int) -> int:
    """The stencil flag of the transparent caster in ``slot`` (0 .. FILTER_SLOTS - 1)."""
    return 1 << (4 + slot)


def _gl():
    from shadelab.gl import lite  # PyOpenGL's raw entry points, checked (gl/lite.py)

    return lite


def heat_color(count: int) -> tuple[float, float, float, float]:
    """Heat-map color of a stencil count (1 = blue ... 8 = red), half transparent."""
    t = (min(count, HEAT_LEVELS) - 1) / (HEAT_LEVELS - 1)
    return (t, 1.0 - abs(2.0 * t - 1.0), 1.0 - t, 0.6)


def light_key(light: Light) -> tuple:
    return (light.kind, tuple(light.position), tuple(light.direction))


@dataclass
class CasterVolume:
    """One caster's volume for one light, on the GPU."""

    key: tuple
    volume: ShadowVolume
    object_index: int
    vbo: moderngl.Buffer
    vao: moderngl.VertexArray
    line_vbo: moderngl.Buffer
    line_vao: moderngl.VertexArray
    # the cheaper caps of a closed caster's volume for the count (None: count with vao)
    counted: CountVolume | None = None
    count_vbo: moderngl.Buffer | None = None
    count_vao: moderngl.VertexArray | None = None
    bounds: np.ndarray | None = None  # the caster's (2, 3) world box (closed casters)
    occluder: PlanarOccluder | None = None  # a flat opaque caster's (set per frame)
    # the counted geometry cut off at a face of the receivers' box (BOUNDED_VOLUMES), for the
    # box and margin in bounded_key; None: no face fits, counted to infinity
    bounded_key: tuple | None = None
    bounded_vbo: moderngl.Buffer | None = None
    bounded_vao: moderngl.VertexArray | None = None
    bounded_points: np.ndarray | None = None  # (M, 4) the cut geometry's vertices, w = 1

    def hidden_from(self, view) -> bool:
        """Is nothing the volume could hold visible from the view's eye (its count 0 on
        every pixel)? Only for a flat opaque caster (:class:`PlanarOccluder`)."""
        return (HIDDEN_VOLUMES_LEFT_OUT and self.occluder is not None
                and self.occluder.hides_volume_from(view.eye, getattr(view, "near_reach",
                                                                      np.inf)))

    def release(self) -> None:
        for item in (self.vao, self.vbo, self.line_vao, self.line_vbo, self.count_vao,
                     self.count_vbo, self.bounded_vao, self.bounded_vbo):
            if item is not None:
                item.release()

    def render_count(self, view, bounded: bool = False) -> None:
        """Draw the volume for the stencil count: its :class:`CountVolume` where there is
        one (the near fan only with the eye outside the caster), else every face;
        ``bounded``: cut off at the receivers' box where that geometry was made."""
        bounded = bounded and self.bounded_vao is not None
        if self.counted is None or not REDUCED_CAPS:
            # (the bounded geometry is the counted volume's where there is one)
            bounded = bounded and self.counted is None
            (self.bounded_vao if bounded else self.vao).render(moderngl.TRIANGLES)
            return
        vao = self.bounded_vao if bounded else self.count_vao
        for first, faces in self.counted.ranges(_eye_outside(view, self.bounds)):
            vao.render(moderngl.TRIANGLES, vertices=3 * faces, first=3 * first)


    def count_points(self, bounded: bool = False) -> np.ndarray:
        """(N, 4) homogeneous world points whose convex hull holds every triangle
        :meth:`render_count` draws with the same ``bounded``."""
        bounded = bounded and self.bounded_vao is not None
        if self.counted is None or not REDUCED_CAPS:
            bounded = bounded and self.counted is None
            return self.bounded_points if bounded else self.volume.vertices
        return self.bounded_points if bounded else self.counted.vertices


def _eye_outside(view, bounds: np.ndarray | None) -> bool:
    """Is the view's eye farther from the box than the near plane reaches (View.near_reach;
    a view without one counts as inside)?"""
    reach = getattr(view, "near_reach", np.inf)
    if bounds is None or not np.isfinite(reach):
        return False
    gap = np.maximum(np.maximum(bounds[0] - view.eye, view.eye - bounds[1]), 0.0)
    return bool(np.linalg.norm(gap) > 1.01 * reach + 1e-9)


class ShadowVolumes:
    """Builds (and caches) shadow-volume geometry and runs the stencil passes."""

    def __init__(self, ctx: moderngl.Context):
        self.ctx = ctx
        self.program = load_program(ctx, "shadow_volume")
        self._cache: dict[tuple, CasterVolume] = {}
        self._closed: dict[tuple, bool] = {}  # geometry key -> closed caster?
        self._convex: dict[tuple, bool] = {}  # geometry key -> convex closed caster?
        self._grouping: dict[tuple, list[list[int]]] = {}  # recent groupings of open casters
        self._skips: dict[tuple, list[bool]] = {}  # recent shadows_nothing answers
        self._occluders: dict[tuple, PlanarOccluder | None] = {}  # recent planar_occluder
        self._offset_key: tuple | None = None   # the meshes _offset_value was measured on
        self._offset_value = 0.0
        self._box = np.zeros((2, 3))            # their (2, 3) world box (the receivers')
        quad = np.array([[-1, -1, 1, 1], [1, -1, 1, 1], [1, 1, 1, 1],
                         [-1, -1, 1, 1], [1, 1, 1, 1], [-1, 1, 1, 1]], dtype=np.float32)
        self._quad_vbo = ctx.buffer(quad.tobytes())
        self._quad_vao = ctx.vertex_array(self.program, [(self._quad_vbo, "4f", "in_position")])

    # ------------------------------------------------------------ geometry
    def volumes(self, scene: Scene, gpu_meshes, light_index: int,
                light: Light) -> list[CasterVolume]:
        """The volumes of every shadow-casting object for one light (cached). A flat caster
        with every other object on the light's side (a floor, a room's walls) is skipped: its
        volume holds no receiver (:func:`shadows_nothing`), the stencil is the same.

        Closed casters get their silhouette volume, transparent ones their own volume (each
        is counted alone for its filter flag); the other open casters are grouped by shared
        corners and each group gets one :func:`open_volume` (the union of their per-triangle
        volumes without the sides that cancel: the same count, far less fill)."""
        offset = self._offset(gpu_meshes)
        homogeneous = light_kind(light).homogeneous()
        out = []
        live = set()
        grouped = []
        skipped = self._skipped(gpu_meshes, light, homogeneous, offset)
        for position, gpu in enumerate(gpu_meshes):
            obj = scene.objects[gpu.mesh.index] if gpu.mesh.index < len(scene.objects) else None
            if obj is None or not obj.cast_shadows or skipped[position]:
                continue
            # kt > 0: renderer.is_transparent (filtered, so counted alone)
            if scene.materials[obj.material].kt <= 0.0 and not self._is_closed(gpu):
                grouped.append(gpu)
                continue
            slot = (gpu.mesh.index, light_index)
            key = (gpu.key, light_key(light), offset)
            live.add(slot)
            out.append(self._bound(self._cached(
                slot, key, gpu.mesh.index, lambda g=gpu: shadow_volume(
                    g.mesh.vertices, g.mesh.faces, homogeneous, offset),
                counted=lambda volume, g=gpu: count_volume(volume, homogeneous,
                                                           self._is_convex(g)),
                bounds=gpu.bounds)))
        for group in self._groups(grouped):
            members = [grouped[i] for i in group]
            slot = (("open",) + tuple(g.mesh.index for g in members), light_index)
            key = (tuple(g.key for g in members), light_key(light), offset)
            live.add(slot)
            caster = self._cached(slot, key, members[0].mesh.index, lambda m=members: (
                open_volume([(g.mesh.vertices, g.mesh.faces) for g in m], homogeneous,
                            offset)))
            caster.occluder = self._occluder(members, gpu_meshes, light, homogeneous, offset)
            out.append(self._bound(caster))
        for slot in [s for s in self._cache if s[1] == light_index and s not in live]:
            self._cache.pop(slot).release()
        return out

    def _offset(self, gpu_meshes) -> float:
        """OFFSET_FRACTION of the scene's diagonal, memoized on every mesh's geometry (scanning
        every vertex each frame cost ~1.5 ms of the lecture frame's main thread)."""
        key = tuple(g.key for g in gpu_meshes)
        if self._offset_key != key:
            self._box = scene_bounds([g.mesh for g in gpu_meshes])
            self._offset_value = OFFSET_FRACTION * float(np.linalg.norm(np.ptp(self._box,
                                                                               axis=0)))
            self._offset_key = key
        return self._offset_value

    def margin(self) -> float:
        """How far beyond the receivers' box (:meth:`_offset`'s) the bounded volumes end."""
        return BOUND_MARGIN * float(np.linalg.norm(np.ptp(self._box, axis=0)))

    def _bound(self, caster: CasterVolume) -> CasterVolume:
        """Give ``caster`` its counted geometry cut off at the receivers' box
        (:func:`bounded_volume`), made again only when the volume or the box changes."""
        key = (caster.key, self._box.tobytes())
        if caster.bounded_key == key:
            return caster
        for item in (caster.bounded_vao, caster.bounded_vbo):
            if item is not None:
                item.release()
        caster.bounded_vao = caster.bounded_vbo = None
        caster.bounded_key = key
        counted = caster.counted
        vertices = caster.volume.vertices if counted is None else counted.vertices
        n = len(caster.volume.vertices) // 2
        cut = bounded_volume(vertices, volume_sources(n, counted is not None), self._box,
                             self.margin())
        caster.bounded_points = None if cut is None else cut[0]
        if cut is not None:
            faces = caster.volume.faces if counted is None else counted.faces
            caster.bounded_vbo = self.ctx.buffer(cut[0][faces].astype(np.float32).tobytes())
            caster.bounded_vao = self.ctx.vertex_array(
                self.program, [(caster.bounded_vbo, "4f", "in_position")])
        return caster

    def bounded_for(self, view, method: str) -> bool:
        """Count with the bounded volumes in this view? z-fail only (z-pass keeps its
        failure with the eye inside a volume), and only while the view's depth steps at the
        grown box's farthest corner are fine enough to tell the far cap from a receiver."""
        near = getattr(view, "near", 0.0)
        if not BOUNDED_VOLUMES or method != "zfail" or not near > 0.0:
            return False
        margin = self.margin()
        corners = box_corners(self._box)
        # (the cut's plane lies up to two margins past the box: bounded_volume)
        farthest = float(np.linalg.norm(corners - view.eye, axis=1).max()) + 3.0 * margin
        step = farthest * farthest / (near * float(1 << 24))
        return step * DEPTH_STEPS_IN_MARGIN < margin

    def screen_rect(self, view, volumes: list[CasterVolume],
                    method: str) -> tuple[int, int, int, int] | None:
        """The window rectangle (x, y, width, height; pixels, from the bottom left) that
        holds every pixel :meth:`count` can change, grown by SCISSOR_PAD pixels; None where
        it cannot be bounded (a drawn point at or behind the eye's plane, clip w <= 0).

        A triangle whose corners all lie in front of the eye projects to the triangle of
        their projections, so the corners' projections bound every fragment the count
        draws; the stencil outside stays at its cleared 0."""
        bounded = self.bounded_for(view, method)
        points = [c.count_points(bounded) for c in volumes if not c.hidden_from(view)]
        if not points:
            return 0, 0, 0, 0
        clip = np.vstack(points) @ np.asarray(view.clip_from_world, dtype=np.float64).T
        w = clip[:, 3]
        if not w.min() > 1e-9 * np.abs(w).max():
            return None
        width, height = view.size
        xs, ys = clip[:, 0] / w, clip[:, 1] / w
        x0 = max(int(np.floor((xs.min() + 1.0) * 0.5 * width)) - SCISSOR_PAD, 0)
        x1 = min(int(np.ceil((xs.max() + 1.0) * 0.5 * width)) + SCISSOR_PAD, width)
        y0 = max(int(np.floor((ys.min() + 1.0) * 0.5 * height)) - SCISSOR_PAD, 0)
        y1 = min(int(np.ceil((ys.max() + 1.0) * 0.5 * height)) + SCISSOR_PAD, height)
        return x0, y0, max(x1 - x0, 0), max(y1 - y0, 0)

    def _occluder(self, members, gpu_meshes, light: Light, homogeneous: np.ndarray,
                  offset: float) -> PlanarOccluder | None:
        """:func:`planar_occluder` of a group of opaque open casters (one flat caster),
        the other meshes' boxes as receivers; memoized on every mesh's geometry."""
        key = (tuple(g.key for g in members), tuple(g.key for g in gpu_meshes),
               light_key(light), offset)

        def compute() -> PlanarOccluder | None:
            vertices, faces, normals, base = [], [], [], 0
            for g in members:
                vertices.append(g.mesh.vertices)
                faces.append(np.asarray(g.mesh.faces) + base)
                normals.append(g.mesh.face_normals)
                base += len(g.mesh.vertices)
            receivers = [g.bounds for g in gpu_meshes if not any(g is m for m in members)]
            return planar_occluder(np.concatenate(vertices), np.concatenate(faces),
                                   np.concatenate(normals), homogeneous, receivers, offset,
                                   1e-6 * offset)

        return memoized(self._occluders, key, compute, RECENT)

    def _skipped(self, gpu_meshes, light: Light, homogeneous: np.ndarray,
                 offset: float) -> list[bool]:
        """:func:`shadows_nothing` of each mesh for this light, memoized on the light and
        every mesh's geometry (the receivers' boxes): it runs again only after an edit."""
        key = (tuple(g.key for g in gpu_meshes), light_key(light), offset)
        return memoized(self._skips, key, lambda: [
            shadows_nothing(gpu.mesh.vertices, gpu.mesh.face_normals, homogeneous,
                            [g.bounds for g in gpu_meshes if g is not gpu], offset)
            for gpu in gpu_meshes], RECENT)

    def _cached(self, slot: tuple, key: tuple, object_index: int, build, counted=None,
                bounds: np.ndarray | None = None) -> CasterVolume:
        """The volume in ``slot`` if it was built for ``key``, else ``build()`` uploaded
        (with ``counted(volume)``, its :class:`CountVolume` or None, for a closed caster
        whose world box is ``bounds``)."""
        cached = self._cache.get(slot)
        if cached is None or cached.key != key:
            if cached is not None:
                cached.release()
            volume = build()
            cached = self._upload(key, object_index, volume)
            reduced = counted(volume) if counted is not None else None
            if reduced is not None:
                cached.counted = reduced
                cached.count_vbo = self.ctx.buffer(reduced.triangles().tobytes())
                cached.count_vao = self.ctx.vertex_array(
                    self.program, [(cached.count_vbo, "4f", "in_position")])
                cached.bounds = np.asarray(bounds, dtype=np.float64)
            self._cache[slot] = cached
        return cached

    def _groups(self, grouped: list) -> list[list[int]]:
        """:func:`open_caster_groups` of these meshes, memoized on their geometry keys."""
        return memoized(self._grouping, tuple(g.key for g in grouped),
                        lambda: open_caster_groups([g.mesh.vertices for g in grouped]), RECENT)

    def _is_closed(self, gpu) -> bool:
        """Does the object's mesh make a closed caster (a silhouette volume)? Memoized."""
        return memoized(self._closed, gpu.key, lambda: closed_caster(
            gpu.mesh.vertices, gpu.mesh.faces) is not None, GEOMETRIES)

    def _is_convex(self, gpu) -> bool:
        """Is the object's mesh a convex closed caster? Memoized per geometry."""
        return memoized(self._convex, gpu.key,
                        lambda: is_convex(gpu.mesh.vertices, gpu.mesh.faces), GEOMETRIES)

    def _upload(self, key: tuple, object_index: int, volume: ShadowVolume) -> CasterVolume:
        vbo = self.ctx.buffer(volume.triangles().tobytes())
        vao = self.ctx.vertex_array(self.program, [(vbo, "4f", "in_position")])
        lines = volume.vertices[volume.silhouette].astype(np.float32)
        line_vbo = self.ctx.buffer(lines.tobytes() if len(lines) else bytes(32))
        line_vao = self.ctx.vertex_array(self.program, [(line_vbo, "4f", "in_position")])
        return CasterVolume(key, volume, object_index, vbo, vao, line_vbo, line_vao)

    def release_volumes(self) -> None:
        """Drop every cached volume and memoized answer (built again on the next frame)."""
        for caster in self._cache.values():
            caster.release()
        self._cache.clear()
        self._skips.clear()
        self._occluders.clear()
        self._grouping.clear()
        self._offset_key = None
        self._closed.clear()
        self._convex.clear()

    def drop_lights_from(self, count: int) -> None:
        for slot in [s for s in self._cache if s[1] >= count]:
            self._cache.pop(slot).release()

    # ------------------------------------------------------------ passes
    def count(self, target, view, volumes: list[CasterVolume], method: str,
              field: int = 0xFF, clear: bool = True) -> None:
        """Stencil pass: clear the stencil and count volume faces (z-fail or z-pass).

        ``field`` limits the clear and the count to those stencil bits (COUNTER_MASK: mod 16,
        leaving the transparent casters' flags alone). ``clear`` False: the caller knows the
        stencil is still 0 from the frame's clear (the first light's count), and the
        stencil-only clear (a masked read-modify-write of the packed depth-stencil buffer on
        llvmpipe) is skipped."""
        GL = _gl()
        ctx = self.ctx
        _ = ctx.error
        target.fbo.color_mask = (False, False, False, False)
        target.fbo.depth_mask = False
        target.fbo.use()  # applies the masks (moderngl sets them on use)
        _ = ctx.error
        GL.glStencilMask(field)
        if clear:
            GL.glClearStencil(0)
            GL.glClear(GL.GL_STENCIL_BUFFER_BIT)
        ctx.enable_only(moderngl.DEPTH_TEST)
        ctx.depth_func = "<"
        GL.glEnable(GL.GL_STENCIL_TEST)
        if method == "zfail":  # far caps at w = 0 may round past depth 1: clamp, never clip
            GL.glEnable(GL.GL_DEPTH_CLAMP)
        GL.glStencilFunc(GL.GL_ALWAYS, 0, 0xFF)
        if method == "zpass":
            GL.glStencilOpSeparate(GL.GL_FRONT, GL.GL_KEEP, GL.GL_KEEP, GL.GL_INCR_WRAP)
            GL.glStencilOpSeparate(GL.GL_BACK, GL.GL_KEEP, GL.GL_KEEP, GL.GL_DECR_WRAP)
        else:
            GL.glStencilOpSeparate(GL.GL_BACK, GL.GL_KEEP, GL.GL_INCR_WRAP, GL.GL_KEEP)
            GL.glStencilOpSeparate(GL.GL_FRONT, GL.GL_KEEP, GL.GL_DECR_WRAP, GL.GL_KEEP)
        set_uniform(self.program, "u_clip_from_world", gl_matrix(view.clip_from_world))
        set_uniform(self.program, "u_color", (0.0, 0.0, 0.0, 0.0))
        bounded = self.bounded_for(view, method)
        for caster in volumes:
            if not caster.hidden_from(view):
                caster.render_count(view, bounded)
        GL.glDisable(GL.GL_DEPTH_CLAMP)
        GL.glStencilOp(GL.GL_KEEP, GL.GL_KEEP, GL.GL_KEEP)
        target.fbo.color_mask = (True, True, True, True)
        target.fbo.use()  # color writes back on; depth writes stay off until the frame ends

    def where_not_zero(self) -> None:
        """Stencil state for the ambient-only pass of one light's shadowed frame
        (Renderer._lit_first_passes): draw only where the count is not 0 (in shadow)."""
        GL = _gl()
        _ = self.ctx.error
        GL.glEnable(GL.GL_STENCIL_TEST)
        GL.glStencilMask(0x00)
        GL.glStencilFunc(GL.GL_NOTEQUAL, 0, 0xFF)
        GL.glStencilOp(GL.GL_KEEP, GL.GL_KEEP, GL.GL_KEEP)

    def lit_where_zero(self, ref: int = 0) -> None:
        """Stencil state for the additive lit pass: draw only where the stencil is ``ref``
        (the volume count 0, and with transparent casters exactly their flags ``ref``)."""
        GL = _gl()
        _ = self.ctx.error
        GL.glEnable(GL.GL_STENCIL_TEST)
        GL.glStencilMask(0x00)
        GL.glStencilFunc(GL.GL_EQUAL, ref, 0xFF)
        GL.glStencilOp(GL.GL_KEEP, GL.GL_KEEP, GL.GL_KEEP)

    def flag_inside(self, target, view, caster: CasterVolume, method: str, slot: int) -> None:
        """Set ``filter_bit(slot)`` wherever the visible surface lies inside ``caster``'s
        volume: count it alone in the counter bits, then turn a non-zero count into the flag
        with a full-screen quad (color and depth untouched)."""
        GL = _gl()
        ctx = self.ctx
        self.count(target, view, [caster], method, field=COUNTER_MASK)
        target.fbo.color_mask = (False, False, False, False)
        target.fbo.use()
        ctx.enable_only(moderngl.NOTHING)
        _ = ctx.error
        GL.glEnable(GL.GL_STENCIL_TEST)
        bit = filter_bit(slot)
        GL.glStencilMask(bit)
        GL.glStencilFunc(GL.GL_NOTEQUAL, bit, COUNTER_MASK)   # bit & 0x0F == 0: count != 0
        GL.glStencilOp(GL.GL_KEEP, GL.GL_KEEP, GL.GL_REPLACE)
        set_uniform(self.program, "u_clip_from_world", np.eye(4, dtype=np.float32).tobytes())
        self._quad_vao.render(moderngl.TRIANGLES)
        GL.glStencilOp(GL.GL_KEEP, GL.GL_KEEP, GL.GL_KEEP)
        target.fbo.color_mask = (True, True, True, True)
        target.fbo.use()

    def stencil_off(self) -> None:
        GL = _gl()
        _ = self.ctx.error
        GL.glDisable(GL.GL_STENCIL_TEST)
        GL.glStencilMask(0xFF)

    # ------------------------------------------------------------ teaching overlays
    def heatmap(self) -> None:
        """Blend a heat-map color over every covered pixel by its current stencil count
        (depth writes are still off from :meth:`count`)."""
        GL = _gl()
        ctx = self.ctx
        ctx.enable_only(moderngl.BLEND)
        ctx.blend_func = moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA
        _ = ctx.error
        GL.glEnable(GL.GL_STENCIL_TEST)
        GL.glStencilMask(0x00)
        GL.glStencilOp(GL.GL_KEEP, GL.GL_KEEP, GL.GL_KEEP)
        ctx.enable(moderngl.DEPTH_TEST)  # the quad sits at depth 1: only covered pixels pass
        ctx.depth_func = ">"
        identity = np.eye(4, dtype=np.float32).tobytes()
        set_uniform(self.program, "u_clip_from_world", identity)
        for level in range(1, HEAT_LEVELS + 1):
            if level < HEAT_LEVELS:
                GL.glStencilFunc(GL.GL_EQUAL, level, 0xFF)
            else:  # 8 and above (a count of -1 wraps to 255 and shows here too)
                GL.glStencilFunc(GL.GL_LEQUAL, level, 0xFF)
            set_uniform(self.program, "u_color", heat_color(level))
            self._quad_vao.render(moderngl.TRIANGLES)
        ctx.depth_func = "<"
        self.stencil_off()

    def draw_translucent(self, target, view, volumes: list[CasterVolume]) -> None:
        """Draw the volumes themselves, translucent, depth-tested against the scene and pushed
        back by a polygon offset: the near cap and the sides' first rows lie on the caster's
        own surface, and drawn at its depth they z-fought with it (a sawtooth terminator). No
        depth is written, so volumes never hide each other or what is drawn after them."""
        GL = _gl()
        ctx = self.ctx
        ctx.enable_only(moderngl.DEPTH_TEST | moderngl.BLEND)
        ctx.blend_func = moderngl.SRC_ALPHA, moderngl.ONE_MINUS_SRC_ALPHA
        target.fbo.depth_mask = False
        target.fbo.use()
        _ = ctx.error
        GL.glDisable(GL.GL_STENCIL_TEST)
        GL.glEnable(GL.GL_DEPTH_CLAMP)
        GL.glEnable(GL.GL_POLYGON_OFFSET_FILL)
        GL.glPolygonOffset(*VOLUME_DEPTH_OFFSET)
        set_uniform(self.program, "u_clip_from_world", gl_matrix(view.clip_from_world))
        set_uniform(self.program, "u_color", VOLUME_COLOR)
        try:
            for caster in volumes:
                caster.vao.render(moderngl.TRIANGLES)
        finally:
            GL.glDisable(GL.GL_POLYGON_OFFSET_FILL)
            GL.glDisable(GL.GL_DEPTH_CLAMP)
            target.fbo.depth_mask = True

    def draw_silhouettes(self, view, volumes: list[CasterVolume]) -> None:
        """Silhouette edges as lines, on top of everything."""
        ctx = self.ctx
        ctx.enable_only(moderngl.NOTHING)
        _ = ctx.error
        _gl().glDisable(_gl().GL_STENCIL_TEST)
        set_uniform(self.program, "u_clip_from_world", gl_matrix(view.clip_from_world))
        set_uniform(self.program, "u_color", SILHOUETTE_COLOR)
        for caster in volumes:
            if len(caster.volume.silhouette):  # open casters: their contour edges
                caster.line_vao.render(moderngl.LINES)

    def release(self) -> None:
        self.release_volumes()
        self._quad_vao.release()
        self._quad_vbo.release()
        self.program.release()


def shadow_masks(renderer, scene: Scene, target, shading: str | None = None) -> np.ndarray:
    """(L, H, W) bool, row 0 at the top: True where light i's stencil count is non-zero
    (S_i = 0) on the frame just drawn. For tests and the viewer's inspection."""
    view = renderer.render(scene, target, shading)
    lights = scene.active_lights()
    gpu_meshes = renderer.sync(scene)
    shadows = renderer.shadow_volumes
    masks = []
    for index, light in enumerate(lights):
        shadows.count(target, view, shadows.volumes(scene, gpu_meshes, index, light),
                      scene.render.shadow_method)
        masks.append(target.read_stencil() != 0)
    shadows.stencil_off()
    target.fbo.depth_mask = True
    target.fbo.use()
    return np.array(masks).reshape(len(lights), target.size[1], target.size[0])
