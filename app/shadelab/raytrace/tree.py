"""The ray tree of one pixel (the lecture's "The Ray Tree" slide) as pure data.

:func:`trace_pixel_tree` traces the pixel-centre ray with the same :class:`TraceContext` steps
as the Whitted renderer, keeping every ray: the primary ray, a shadow ray per light at each
hit, and the reflected and refracted rays. The contributions of all nodes add up to the
pixel's 1-spp value. The viewer draws the tree in 3D and lists it with :meth:`RayNode.flatten`.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Iterator

import numpy as np

from shadelab.raytrace.accel import Hits
from shadelab.raytrace.surface import TraceContext
from shadelab.raytrace.whitted import check_settings
from shadelab.scene.camera import primary_rays
from shadelab.scene.model import Scene
from shadelab.shading.lights import light_kind
from shadelab.shading.reference import light_vectors

RAY_KINDS = ("primary", "shadow", "reflected", "refracted")


@dataclass
class RayNode:
    """One ray of the tree.

    Attributes
    ----------
    kind : "primary" | "shadow" | "reflected" | "refracted"
    origin : (3,) world space start (offset off the surface for secondary rays)
    direction : (3,) unit
    end : (3,) the hit point (shadow ray: the blocker's hit, or the light's position when
        lit; a directional light's lit ray has no end), or None for a miss
    object : index into ``scene.objects`` of the object hit (blocker for a shadow ray), or -1
    weight : (3,) product of the kr / kt weights from the pixel down to this ray
    local : (3,) the local model at the hit (background for a miss; zero for shadow rays)
    contribution : (3,) weight * local, this ray's share of the pixel (RGB)
    depth : generation (0 for the primary ray and its shadow rays)
    light : for a shadow ray, the index of its light among the enabled lights
    shadow : for a shadow ray, S_i (1 lit, 0 blocked)
    children : shadow rays first, then the reflected and refracted rays
    """

    kind: str
    origin: np.ndarray
    direction: np.ndarray
    end: np.ndarray | None
    object: int
    weight: np.ndarray
    local: np.ndarray
    contribution: np.ndarray
    depth: int = 0
    light: int = -1
    shadow: float = 1.0
    children: list[RayNode] = field(default_factory=list)

    def flatten(self, depth: int = 0) -> Iterator[tuple[int, RayNode]]:
        """(depth in the tree, node) for this node and every descendant, depth first."""
        yield depth, self
        for child in self.children:
            yield from child.flatten(depth + 1)

    def total(self) -> np.ndarray:
        """Sum of the contributions of the whole tree: the pixel's value (RGB)."""
        return sum((node.contribution for _, node in self.flatten()), np.zeros(3))


def pixel_ray(scene: Scene, size: tuple[int, int], x: int, y: int):
    """Origin and unit direction through the centre of pixel (x, y), row 0 at the top."""
    width, height = size
    if not (0 <= x < width and 0 <= y < height):
        raise ValueError(f"pixel ({x}, {y}) outside a {width}x{height} image")
    origins, dirs = primary_rays(scene.camera, width, height)
    return origins[y, x].copy(), dirs[y, x].copy()


def trace_pixel_tree(scene: Scene, size: tuple[int, int], x: int, y: int,
                     depth: int | None = None, fresnel: bool | None = None,
                     ctx: TraceContext | None = None) -> RayNode:
    """The ray tree of pixel (x, y) of a ``size`` = (width, height) image."""
    depth = scene.raytrace.depth if depth is None else int(depth)
    fresnel = scene.raytrace.fresnel if fresnel is None else bool(fresnel)
    check_settings(depth, 1, size)
    ctx = TraceContext(scene) if ctx is None else ctx
    origin, direction = pixel_ray(scene, size, x, y)
    return _trace(ctx, "primary", origin, direction, np.ones(3), 0, depth, fresnel)


def _trace(ctx: TraceContext, kind: str, origin: np.ndarray, direction: np.ndarray,
           weight: np.ndarray, generation: int, depth: int, fresnel: bool) -> RayNode:
    o, d = origin[None], direction[None]
    hits = ctx.accel.intersect(o, d)
    if not hits.hit[0]:
        return RayNode(kind, origin, direction, None, -1, weight, ctx.background.copy(),
                       weight * ctx.background, generation)
    one = Hits(hits.t, hits.tri, hits.u, hits.v)
    surf = ctx.surface(o, d, one)
    shadow = ctx.shadow_factors(surf)
    local = ctx.local(surf, d, shadow)[0]
    node = RayNode(kind, origin, direction, surf.position[0].copy(), int(surf.obj[0]), weight,
                   local, weight * local, generation)
    node.children.extend(_shadow_nodes(ctx, surf, shadow, weight, generation))
    if generation == depth:
        return node
    refl_dir, refl_w, refr_dir, refr_w = ctx.secondary(surf, d, fresnel)
    threshold = max(ctx.scene.raytrace.min_weight, 1e-12)
    for child_kind, child_dir, child_w, outward in (("reflected", refl_dir, refl_w, True),
                                                     ("refracted", refr_dir, refr_w, False)):
        w = weight * child_w[0]
        if w.max() >= threshold:
            start = ctx.offset_origin(surf, np.array([0]), outward)[0]
            node.children.append(_trace(ctx, child_kind, start, child_dir[0], w,
                                        generation + 1, depth, fresnel))
    return node


def _shadow_nodes(ctx: TraceContext, surf, shadow: list, weight: np.ndarray,
                  generation: int) -> list[RayNode]:
    """One node per light: where the shadow ray went and what (if anything) blocked it."""
    nodes = []
    for i, light in enumerate(ctx.lights):
        to_light, distance = light_vectors(light, surf.position)
        start = surf.position[0] + ctx.eps * surf.geo_normal[0]
        lit = float(np.max(shadow[i][0]))  # S_i, or its largest channel (kt-filtered)
        end = light_kind(light).end()
        blocker = -1
        if lit == 0.0:  # blocked, or the light is behind the surface: find the blocker
            hits = ctx.accel.intersect(start[None], to_light[:1])
            far = distance[0] if np.isfinite(distance[0]) else np.inf
            if hits.hit[0] and hits.t[0] < far:
                end = start + hits.t[0] * to_light[0]
                blocker = int(ctx.geometry.object_index[hits.tri[0]])
        nodes.append(RayNode("shadow", start, to_light[0].copy(), end, blocker, weight,
                             np.zeros(3), np.zeros(3), generation, light=i, shadow=lit))
    return nodes
