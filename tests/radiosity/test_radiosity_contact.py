"""Contact shadows: a scanned mesh of more than 100k triangles standing on a floor
(``presets/mesh-spot.toml``: Spot, Loop-subdivided twice and its 2,200 largest triangles split
again: 100,296 triangles) at the default budget of 400 patches.

The mesh is clustered to its share of the budget (:func:`shadelab.radiosity.patches.cluster_mesh`)
and discontinuity meshing refines the floor where it matters: cells near the mesh are split
while closer to it than ``meshing.NEAR_REACH`` of their size, ``NEAR_LEVELS`` times, and cells
across the point light's shadow boundary once. The floor's direct light is shadowed by the
mesh's own triangles (:mod:`shadelab.radiosity.direct`), not by its ~200 clusters.

The contact shadow is measured in the radiosity image of the floor seen from below (the floor's
radiance as drawn, Gouraud across the patches): pixels under the mesh's footprint that lie in
its shadow (a ray to the light meets the mesh) against lit pixels beside the footprint (within
0.4 m of it). Measured: 0.095 of the lit floor's radiance (indirect light only); with the
refinement near the mesh off (``NEAR_LEVELS = 0``, the floor's 1.1 m cells split once across the
shadow) 0.22: the coarse cells smear the lit floor into the shadow. Bound: 0.15.
"""

from __future__ import annotations

import time

import numpy as np
import pytest
import trimesh

from shadelab.geometry.mesh import scene_meshes
from shadelab.radiosity.solution import solve_scene
from shadelab.resources import presets_dir
from shadelab.scene.camera import primary_rays
from shadelab.scene.preset import load_preset

CONTACT_BOUND = 0.15  # shadowed floor under the mesh / lit floor beside it (measured 0.095)
SIZE = 128  # pixels of the floor image seen from below


@pytest.fixture(scope="module")
def solved(tmp_path_factory):
    spot = trimesh.load(presets_dir() / "meshes" / "spot.obj", process=False, force="mesh")
    vertices, faces = trimesh.remesh.subdivide_loop(spot.vertices, spot.faces, iterations=2)
    tri = vertices[faces]
    area = np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    vertices, faces = trimesh.remesh.subdivide(vertices, faces,
                                               face_index=np.argsort(-area)[:2200])
    path = tmp_path_factory.mktemp("spot") / "spot-100k.ply"
    trimesh.Trimesh(vertices, faces, process=False).export(path)
    scene = load_preset("mesh-spot", [f"objects.1.path={path}"])
    mesh = scene_meshes(scene)[1]
    start = time.perf_counter()
    solution = solve_scene(scene)  # the preset's budget, meshing and solver
    seconds = time.perf_counter() - start
    print(f"\n{len(mesh.faces)} triangles -> {len(solution.patches)} patches in {seconds:.2f} s "
          f"(meshing {solution.stats['meshing_s']:.2f} s, form factors "
          f"{solution.stats['form_factors_s']:.2f} s)")
    return scene, mesh, solution


def _embree(triangles: np.ndarray):
    import embreex.mesh_construction as mc
    import embreex.rtcore_scene as rs

    scene = rs.EmbreeScene()
    mc.TriangleMesh(scene, np.ascontiguousarray(triangles, np.float32))
    return scene


def _under(mesh, points: np.ndarray) -> np.ndarray:
    """Floor points with the mesh straight above them."""
    up = np.tile(np.float32([0.0, 1.0, 0.0]), (len(points), 1))
    origins = (points + [0.0, 1e-4, 0.0]).astype(np.float32)
    return _embree(mesh.vertices[mesh.faces]).run(origins, up) != -1


def test_the_scan_fits_the_budget(solved):
    scene, mesh, solution = solved
    assert len(mesh.faces) >= 100_000
    patches = solution.patches
    assert patches.info["clustered"] and patches.info["mesh_triangles"] == len(mesh.faces)
    assert len(patches) <= scene.radiosity.patches == 400
    assert len(patches) >= 0.85 * scene.radiosity.patches


def test_the_floor_is_finer_under_the_scan(solved):
    """Floor cells under the mesh are at least two quadtree levels (1/16 of the area) below
    the largest floor cell, most of them three (1/64), and there are many of them (measured
    67, and 9 without the refinement near the mesh, none of them split twice)."""
    _, mesh, solution = solved
    p = solution.patches
    floor = p.surface == 0
    under = floor & _under(mesh, p.centers)
    assert under.sum() >= 40
    largest = p.areas[floor].max()
    assert p.areas[under].max() <= largest / 16.0 * (1.0 + 1e-9)
    assert np.mean(p.areas[under] <= largest / 64.0 * (1.0 + 1e-9)) >= 0.9


def test_the_scan_casts_its_contact_shadow(solved):
    scene, mesh, solution = solved
    scene.camera.eye = [0.0, -4.0, 0.001]  # below the floor, looking up at its underside
    scene.camera.target = [0.0, 0.0, 0.0]
    scene.camera.up = [0.0, 0.0, 1.0]
    scene.camera.fov_y = 40.0
    image = solution.image((SIZE, SIZE)).mean(axis=2).reshape(-1)
    origins, dirs = primary_rays(scene.camera, SIZE, SIZE)
    origins, dirs = origins.reshape(-1, 3), dirs.reshape(-1, 3)
    points = origins - (origins[:, 1] / dirs[:, 1])[:, None] * dirs  # on the floor, y = 0
    under = _under(mesh, points)
    light = np.asarray(scene.lights[0].position, float)
    start = points + [0.0, 1e-4, 0.0]
    to_light = light - start
    reach = np.linalg.norm(to_light, axis=1)
    shadow = _embree(mesh.vertices[mesh.faces]).run(
        start.astype(np.float32), (to_light / reach[:, None]).astype(np.float32),
        dists=(reach - 1e-3).astype(np.float32), query="OCCLUDED") != -1
    from scipy.spatial import cKDTree

    footprint = cKDTree(mesh.vertices[mesh.vertices[:, 1] < 0.6][:, [0, 2]])
    distance, _ = footprint.query(points[:, [0, 2]])
    dark = under & shadow
    lit = ~under & ~shadow & (distance < 0.4)
    assert dark.sum() > 500 and lit.sum() > 500  # (measured 1297 and 1488 pixels)
    assert image[lit].min() > 0.0
    ratio = float(image[dark].mean() / image[lit].mean())
    assert ratio <= CONTACT_BOUND, f"{ratio:.3f}"
