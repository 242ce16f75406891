"""Textured materials at ray hits: Od(u, v) and the bumped normal, as the raster's ``*_tex``
programs (see :mod:`shadelab.shading.surface_detail`).

At a hit on triangle f with barycentrics (u, v): uv = (1 - u - v) uv0 + u uv1 + v uv2 (the
raster's interpolated ``v_uv``), dP/du and dP/dv constant per triangle (the geometry shader's
``triangle_tangents``). Only hits on materials with a texture or a bump are reshaded (with
:func:`shadelab.shading.reference.shade` and a per-point Od), so every other material keeps
the tracers' output bit for bit.
"""

from __future__ import annotations

import numpy as np

from shadelab.shading.reference import shade
from shadelab.shading.surface_detail import MaterialDetail, has_surface_detail, triangle_tangents


class SceneDetail:
    """The textured materials of a TraceContext (``active`` is False when there are none)."""

    def __init__(self, ctx):
        self.ctx = ctx
        g = ctx.geometry
        self.details: dict[int, MaterialDetail] = {}
        if g.corner_uvs is not None and g.count:
            for i, (name, m) in enumerate(zip(ctx.material_names, ctx.materials, strict=True)):
                if has_surface_detail(m):
                    self.details[i] = MaterialDetail(name, m, ctx.scene.base_dir)
        self.active = bool(self.details)
        self._tangents = None

    def tangents(self) -> tuple[np.ndarray, np.ndarray]:
        if self._tangents is None:
            g = self.ctx.geometry
            self._tangents = triangle_tangents(g.triangles, g.corner_uvs)
        return self._tangents

    def hit_uv(self, tri: np.ndarray, u: np.ndarray, v: np.ndarray) -> np.ndarray:
        """(N, 2) interpolated texture coordinates at the hits."""
        c = self.ctx.geometry.corner_uvs[tri]
        return (1.0 - u - v)[:, None] * c[:, 0] + u[:, None] * c[:, 1] + v[:, None] * c[:, 2]

    def od_and_normal(self, m: int, tri, u, v, normal):
        """Per-hit Od (N, 3) and bumped normal (N, 3) for hits on material index ``m``."""
        detail = self.details[m]
        uv = self.hit_uv(tri, u, v)
        dpdu, dpdv = self.tangents()
        return detail.od(uv), detail.normal(normal, dpdu[tri], dpdv[tri], uv)

    def bumped(self, normal: np.ndarray, dirs: np.ndarray, mat: np.ndarray, tri: np.ndarray,
               u: np.ndarray, v: np.ndarray) -> np.ndarray:
        """The normals mirror and refracted rays leave about: ``normal`` with the bumped
        normal on bumped materials (the one :meth:`reshade` shades with), where it still faces
        the incoming ray. ``normal`` itself when no hit is on a bumped material."""
        out = normal
        for m, detail in self.details.items():
            if not detail.bump_mode:
                continue
            idx = np.flatnonzero(mat == m)
            if len(idx) == 0:
                continue
            _, n = self.od_and_normal(m, tri[idx], u[idx], v[idx], normal[idx])
            facing = np.einsum("ij,ij->i", n, -dirs[idx]) > 0.0
            if out is normal:
                out = normal.copy()
            out[idx[facing]] = n[facing]
        return out

    def reshade(self, color: np.ndarray, position: np.ndarray, normal: np.ndarray,
                dirs: np.ndarray, mat: np.ndarray, tri: np.ndarray, u: np.ndarray,
                v: np.ndarray, shadow) -> np.ndarray:
        """Overwrite ``color`` (N, 3) at hits on textured materials. ``shadow``: S per light,
        (L, N) or a list of (N,), or (L, N, 3) per channel (kt-filtered)."""
        ctx = self.ctx
        shadow = np.asarray(shadow, dtype=np.float64).reshape(len(ctx.lights), len(color),
                                                              *np.shape(shadow)[2:])
        for m in self.details:
            idx = np.flatnonzero(mat == m)
            if len(idx) == 0:
                continue
            t = tri[idx]
            od, n = self.od_and_normal(m, t, u[idx], v[idx], normal[idx])
            pos = position[idx]
            eye = pos - dirs[idx]
            s = shadow[:, idx]
            if s.ndim == 3:
                for c in range(3):
                    color[idx, c] = shade(pos, n, eye, ctx.materials[m], ctx.lights, ctx.Ia,
                                          ctx.specular, list(s[..., c]), od)[:, c]
            else:
                color[idx] = shade(pos, n, eye, ctx.materials[m], ctx.lights, ctx.Ia,
                                   ctx.specular, list(s), od)
        return color
