"""The lecture's point, spot and directional lights in radiosity: their direct light is the
first shot.

Units (ARCHITECTURE.md §2, the same reading as the path tracer, :mod:`shadelab.raytrace.pathtrace`):
a lecture light of intensity Ip is a point source of radiant intensity pi * Ip for the diffuse
BRDF rho / pi, so a patch at distance d whose normal makes the angle theta with the direction to
the light receives the irradiance

    H = S * f_att(d) * spot * pi * Ip * cos(theta)        (f_att: the light's attenuation mode,
                                                           1 for a directional light)

and reflects the radiosity ``E_direct = rho * H`` (B = pi L). Its radiance E_direct / pi =
S f_att spot Ip kd Od cos(theta) is then exactly the raster's diffuse term, so on a lambertian
floor radiosity's first bounce equals the raster (no ambient term: the bounces carry the light
it stood for). ``E_direct`` joins the emitters' pi * Le as the right-hand side of
B = E + rho F B, so every solver shoots or gathers it from the first step on.

S, the shadow factor, comes from shadow rays (``raytrace.accel``, the shadow casters only, as
in Whitted) cast against the patches themselves (:func:`patch_accel`: a clustered mesh's
patches lie inside the original surface, which would shadow them) from ``SAMPLES`` points
of each patch (the centre and the corners pulled a quarter of the way in) to the light; H
is their mean. Lights marked ``stand_in`` stand for an emitting surface that radiosity meshes
itself, and are skipped. Pure numpy + the ray-cast accelerator.
"""

from __future__ import annotations

import math

import numpy as np

from shadelab.radiosity.patches import PatchSet
from shadelab.scene.model import Light, Scene
from shadelab.shading.lights import light_kind

INSET = 0.25  # corner samples pulled this share of the way to the centre
SAMPLES = 5   # centre + 4 corners


def direct_lights(scene: Scene) -> list[Light]:
    """The lights radiosity adds as a first shot: enabled and not a ``stand_in``."""
    return [light for light in scene.active_lights() if not light.stand_in]


def light_label(light: Light, index: int) -> str:
    return light.name or f"{light.kind} {index}"


def sample_points(patches: PatchSet) -> np.ndarray:
    """(N, SAMPLES, 3): each patch's centre and its corners pulled ``INSET`` towards it."""
    centre = patches.centers[:, None, :]
    corners = patches.polygons + INSET * (centre - patches.polygons)
    return np.concatenate([centre, corners], axis=1)


def irradiance(light: Light, points: np.ndarray, normals: np.ndarray,
               occluded=None, eps: float = 0.0) -> np.ndarray:
    """(P,) irradiance H = S f_att spot pi Ip_c cos(theta) per point, one channel-free factor:
    the returned value multiplies ``Ip`` (so H_c = value * Ip_c).

    ``occluded(origins, dirs, tmax) -> bool`` gives S (None: nothing casts shadows); origins
    move ``eps`` along the normal."""
    kind = light_kind(light)
    to_light, distance = kind.to_light(points)
    cos = np.maximum(np.einsum("ij,ij->i", to_light, normals), 0.0)
    value = math.pi * cos * kind.attenuation(distance) * kind.spot(to_light)
    if occluded is not None:
        lit = np.flatnonzero(value > 0.0)
        if len(lit):
            origins = points[lit] + eps * normals[lit]
            tmax = np.where(np.isfinite(distance[lit]), distance[lit] - eps, np.inf)
            blocked = occluded(origins, to_light[lit], tmax)
            value[lit[blocked]] = 0.0
    return value


def patch_accel(scene: Scene, patches: PatchSet):
    """A ``raytrace.accel`` accelerator of the patches' triangles (two per quad patch), shadow
    casters after their objects' ``cast_shadows``."""
    from shadelab.raytrace.accel import SceneGeometry, build_accel

    poly = patches.polygons
    tris = np.concatenate([poly[:, [0, 1, 2]], poly[:, [0, 2, 3]]])
    owner = np.concatenate([patches.surface, patches.surface])
    cross = np.cross(tris[:, 1] - tris[:, 0], tris[:, 2] - tris[:, 0])
    length = np.linalg.norm(cross, axis=1)
    keep = length > 1e-12 * max(float(length.max(initial=0.0)), 1e-300)
    tris, owner, normals = tris[keep], owner[keep], cross[keep] / length[keep, None]
    if patches.surfaces:
        casts = np.array([scene.objects[s.object_index].cast_shadows
                          for s in patches.surfaces], bool)[owner]
    else:
        casts = np.ones(len(tris), bool)
    points = tris.reshape(-1, 3)
    diagonal = float(np.linalg.norm(np.ptp(points, axis=0))) if len(points) else 1.0
    geometry = SceneGeometry(tris, normals, np.repeat(normals[:, None, :], 3, axis=1),
                             owner, casts, diagonal or 1.0)
    return build_accel(geometry)


def _on_clustered_mesh(patches: PatchSet) -> np.ndarray | None:
    """(N,) bool: patches of a clustered mesh, when the patch set has any (else None)."""
    if not (patches.info.get("clustered") and patches.surfaces):
        return None
    return np.array([s.kind == "mesh" for s in patches.surfaces], bool)[patches.surface]


def direct_radiosity(scene: Scene, patches: PatchSet, shadows: bool = True,
                     accel=None, rho: np.ndarray | None = None) -> tuple[np.ndarray, dict]:
    """(N, 3) E_direct = rho * H per patch and, per light (by label), the power it puts on
    the patches, sum_i A_i H_i (mean over RGB, the scene's units of pi Ip times area), as
    ``{"label": power}``.

    ``accel``: a ``raytrace.accel`` accelerator (default: :func:`patch_accel`); ``rho``:
    (N, 3) reflectance (default: the patches' own)."""
    rho = patches.rho if rho is None else rho
    lights = direct_lights(scene)
    n = len(patches)
    out = np.zeros((n, 3))
    power: dict[str, float] = {}
    if not lights or n == 0:
        return out, power
    occluded, eps = None, 0.0
    if shadows:
        if accel is None:
            accel = patch_accel(scene, patches)
        eps = scene.raytrace.offset * accel.geometry.diagonal
        occluded = accel.occluded
    # Shadow rays where meshes are clustered: a clustered mesh's own patches test against
    # the patches (they lie inside the original surface, which would shadow them); every
    # other patch (a floor under a scan) against the scene's own triangles, so the scan
    # casts the shadow the raster and the path tracer show, not its clusters' (coarse, with
    # gaps between them)
    on_mesh = _on_clustered_mesh(patches) if shadows else None
    if on_mesh is not None and not on_mesh.all():
        from shadelab.raytrace.accel import build_accel, scene_geometry

        original = build_accel(scene_geometry(scene)).occluded
    points = sample_points(patches).reshape(-1, 3)
    normals = np.repeat(patches.normals, SAMPLES, axis=0)
    for index, light in enumerate(lights):
        if on_mesh is None or on_mesh.all():
            h = irradiance(light, points, normals, occluded, eps)
        else:
            mesh = np.repeat(on_mesh, SAMPLES)
            h = np.empty(len(points))
            h[mesh] = irradiance(light, points[mesh], normals[mesh], occluded, eps)
            h[~mesh] = irradiance(light, points[~mesh], normals[~mesh], original, eps)
        h = h.reshape(n, SAMPLES).mean(axis=1)
        H = h[:, None] * np.asarray(light.Ip, float)[None, :]
        out += rho * H
        label = light_label(light, index)
        power[label] = power.get(label, 0.0) + float((patches.areas[:, None] * H).sum() / 3.0)
    return out, power


def describe(power: dict, emitted: float) -> str:
    """One line: what the lights and the emitters put into the scene."""
    parts = [f"{name} {watts:.3g}" for name, watts in power.items()]
    if emitted > 0.0:
        parts.append(f"emitters {emitted:.3g}")
    return "power onto the patches: " + (", ".join(parts) if parts else "none")
