"""Drawn shadow volumes (``render.show_volumes``) do not z-fight with their casters.

A silhouette volume's cap is the caster's own dark side, and its sides start on the
terminator: drawn at the caster's depth they fought with it (sawtooth terminators in the
lesson's shadow-volume step). Oracle: Embree primary rays against the volumes (made finite)
say which pixels a volume face really covers (lies in front of the visible surface by more
than a tolerance); everywhere else the frame with volumes shown equals the frame without."""

from __future__ import annotations

import numpy as np
import pytest
import trimesh

from shadelab.geometry.mesh import scene_bounds, scene_meshes
from shadelab.geometry.silhouette import shadow_volume
from shadelab.raster.offscreen import render_image
from shadelab.scene.camera import primary_rays
from shadelab.scene.preset import load_preset
from shadelab.shading.lights import light_kind

pytestmark = pytest.mark.gl
SIZE = (200, 150)
# Distances in units of the scene's diagonal. SEAM: a side wall this close to the visible
# surface lies on it (the wall's root hugs the caster along the terminator): drawn at the
# caster's depth it z-fought (84-87 % of those pixels tinted, in a sawtooth); it must stay
# under SEAM_SHARE. FAR: a wall clearly in front of the surface must still be drawn.
SEAM, FAR, SEAM_SHARE = 0.002, 0.01, 0.25


def _first_hits(mesh: trimesh.Trimesh, origins, dirs) -> np.ndarray:
    """Distance to the first hit per ray (inf for a miss)."""
    t = np.full(len(origins), np.inf)
    locations, rays, _ = mesh.ray.intersects_location(origins, dirs, multiple_hits=False)
    t[rays] = np.linalg.norm(locations - origins[rays], axis=1)
    return t


def _volume_cover(scene) -> tuple[np.ndarray, np.ndarray]:
    """(H, W) distance to the visible surface and to the nearest side wall or far cap per
    pixel. The near cap is left out: it is the caster's own dark side, covering nothing (that
    cap drawn at the caster's depth is the z-fighting this file tests)."""
    meshes = scene_meshes(scene)
    diag = float(np.linalg.norm(np.ptp(scene_bounds(meshes), axis=0)))
    w, h = SIZE
    origins, dirs = primary_rays(scene.camera, w, h)
    origins, dirs = origins.reshape(-1, 3), dirs.reshape(-1, 3)
    surface = trimesh.util.concatenate([trimesh.Trimesh(m.vertices, m.faces, process=False)
                                        for m in meshes])
    t_surface = _first_hits(surface, origins, dirs)
    parts = []
    for light in scene.active_lights():
        homogeneous = light_kind(light).homogeneous()
        for m in meshes:
            obj = scene.objects[m.index]
            if not obj.cast_shadows or obj.shape in ("plane", "quad"):
                continue  # flat floors and walls shadow nothing here (shadows_nothing)
            volume = shadow_volume(m.vertices, m.faces, homogeneous)
            assert volume.method == "silhouette"  # closed casters: sides, near cap, far cap
            vertices, faces = volume.finite(4 * diag)
            n_dark = (len(faces) - 2 * len(volume.silhouette)) // 2
            keep = np.r_[0:2 * len(volume.silhouette), len(faces) - n_dark:len(faces)]
            parts.append(trimesh.Trimesh(vertices, faces[keep], process=False))
    t_volume = _first_hits(trimesh.util.concatenate(parts), origins, dirs)
    return (t_surface / diag).reshape(h, w), (t_volume / diag).reshape(h, w)


@pytest.mark.parametrize("preset", ["shadows", "lecture"])
def test_drawn_volumes_change_only_the_pixels_they_cover(gl_ctx, preset):
    plain = load_preset(preset, ["render.shadows=volumes"])
    shown = load_preset(preset, ["render.shadows=volumes", "render.show_volumes=true"])
    a, b = render_image(plain, SIZE), render_image(shown, SIZE)
    changed = np.abs(a - b).max(axis=2) > 1e-6
    t_surface, t_volume = _volume_cover(plain)
    with np.errstate(invalid="ignore"):  # inf - inf where a ray meets nothing at all
        gap = t_volume - t_surface       # < 0: a wall or far cap in front of the surface
    seen = np.isfinite(t_surface)
    away = seen & (gap >= SEAM)           # nothing in front, nor on the surface
    seam = seen & (np.abs(gap) < SEAM)    # a wall lying on the caster's surface
    covered = seen & (gap < -FAR)
    assert away.sum() > 1000 and seam.sum() > 100 and covered.sum() > 200
    assert changed[away].sum() == 0
    assert changed[seam].mean() <= SEAM_SHARE, changed[seam].mean()   # no z-fighting
    assert changed[covered].mean() >= 0.95, changed[covered].mean()   # still drawn
