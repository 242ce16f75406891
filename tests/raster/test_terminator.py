"""The shadow terminator on smooth meshes (issue 12, item 10).

Stencil shadow volumes follow the faces: every face turned from the light lies inside its own
volume (S_i = 0), while the interpolated normal of such a face can still see the light, up to
N.L = t = sin(delta), delta the widest face-to-corner normal angle of the mesh. Without care
the lit side steps down to the ambient term along the faceted silhouette and the grazing side
walls stripe the band. The lit pass fades S_i by smoothstep(t, 2t, N.L) (the same function in
numpy and GLSL), so the two sides meet at 0 with no step.

The tests: the bound that makes it exact (closed form over every face of a smooth torus), the
numpy function, and the GL frame of a smooth closed mesh with shadows on against the numpy
reference with S_i from independent Embree shadow rays (``oracle_masks``) and the softening.
"""

from __future__ import annotations

import numpy as np
import pytest
from test_shadows import SIZE, oracle_masks, pixel_surfaces

from shadelab.geometry.mesh import scene_meshes
from shadelab.scene import load_preset
from shadelab.shading.reference import shade, terminator_softening

TORUS = ["objects.1.shape=torus", "objects.1.radius=0.8", "objects.1.minor_radius=0.35",
         "objects.1.sections=24", "objects.1.normals=angle", "objects.1.translate=[-1.0,0.75,0.0]",
         "objects.1.rotate=[40.0,0.0,20.0]", "render.shading=phong",
         "camera.eye=[-1.0,2.0,3.0]", "camera.target=[-1.0,0.7,0.0]"]


def torus_scene(*extra: str):
    return load_preset("shadows", [*TORUS, *extra])


def test_softening_is_the_smoothstep_between_t_and_2t():
    t = 0.2
    x = np.array([-1.0, 0.0, 0.2, 0.25, 0.3, 0.35, 0.4, 1.0])
    u = np.clip((x - t) / t, 0, 1)
    np.testing.assert_allclose(terminator_softening(x, t), u * u * (3 - 2 * u), atol=0)
    assert terminator_softening(np.array(0.3), t) == pytest.approx(0.5)
    np.testing.assert_array_equal(terminator_softening(x, 0.0), np.ones_like(x))  # flat: off


def test_every_face_turned_from_the_light_has_shading_normals_below_t():
    """The closed form behind the fade: Ns.L <= sin(delta) on every face with Ng.L <= 0, for
    any light direction (here 200 of them), at the corners and inside the faces."""
    scene = torus_scene()
    mesh = scene_meshes(scene)[1]
    t = mesh.terminator
    assert 0.05 < t < 0.5                               # a smooth, coarse mesh
    rng = np.random.default_rng(7)
    dirs = rng.normal(size=(200, 3))
    dirs /= np.linalg.norm(dirs, axis=1, keepdims=True)
    weights = rng.dirichlet(np.ones(3), size=16)        # points inside each face
    inside = np.einsum("sc,fck->fsk", weights, mesh.corner_normals)
    inside /= np.linalg.norm(inside, axis=-1, keepdims=True)
    for d in dirs:
        away = mesh.face_normals @ d <= 0.0
        assert (mesh.corner_normals[away] @ d).max() <= t + 1e-12
        assert (inside[away] @ d).max() <= t + 1e-12
    # and the bound is tight: some corner reaches it
    cosine = np.einsum("fk,fck->fc", mesh.face_normals, mesh.corner_normals)
    assert np.sqrt(1 - cosine.min() ** 2) == pytest.approx(t)


def test_flat_meshes_have_no_threshold():
    scene = load_preset("shadows")
    floor, sphere, box = scene_meshes(scene)
    assert floor.terminator == 0.0 and box.terminator == 0.0 and sphere.terminator > 0.0
    flat = scene_meshes(torus_scene("objects.1.normals=flat"))[1]
    assert flat.terminator == 0.0


def _torus_pixels(scene):
    """Per pixel on the torus: pixel number, position, Phong normal, the point's t, face
    normal."""
    ray, position, normal, ng, t = pixel_surfaces(scene, 1, thresholds=True)
    return ray, position, normal, t, ng


def test_smooth_closed_mesh_lit_side_matches_the_shadow_ray_oracle(gl_ctx):
    """GL shadows-on frame on a smooth torus == the numpy reference with S_i from Embree shadow
    rays times the terminator fade, on >= 99 % of its pixels within 0.01 (and the median
    within 1e-4); without the fade the band near the terminator was off by up to kd Ip 2t."""
    from shadelab.raster.offscreen import render_image

    scene = torus_scene()
    image = render_image(scene, SIZE).reshape(-1, 3)
    blocked, _matters = oracle_masks(scene)
    ray, position, normal, t, ng = _torus_pixels(scene)
    assert len(ray) > 1500
    material = scene.materials[scene.objects[1].material]
    lit = ~blocked[0].reshape(-1)[ray]
    want = shade(position, normal, np.asarray(scene.camera.eye), material,
                 scene.active_lights(), scene.Ia, shadow=[lit.astype(float)], terminator=t)
    err = np.abs(image[ray] - want).max(axis=1)
    assert np.mean(err < 0.01) >= 0.99, np.sort(err)[-20:]
    assert np.median(err) < 1e-4
    # the fade really acts here: pixels in the band (t < N.L < 2t) on the lit side
    light = np.asarray(scene.lights[0].position, float)
    to_light = light - position
    n_dot_l = np.einsum("rk,rk->r", normal, to_light / np.linalg.norm(to_light, axis=1)[:, None])
    band = lit & (n_dot_l > t) & (n_dot_l < 2 * t)
    assert band.sum() > 50
    unsoftened = shade(position, normal, np.asarray(scene.camera.eye), material,
                       scene.active_lights(), scene.Ia, shadow=[lit.astype(float)])
    assert np.abs(image[ray][band] - unsoftened[band]).max() > 0.02


def test_no_step_between_lit_faces_and_faces_in_their_own_volume(gl_ctx):
    """Along the torus's own terminator (the pixels where the stencil switches from lit to
    self-shadowed) the light's term is 0 on both sides: the frame equals the ambient-only
    frame there, to 1e-5, where before the fix it jumped by up to kd Od Ip t."""
    from shadelab.raster.offscreen import render_image

    scene = torus_scene()
    shadowed = render_image(scene, SIZE).reshape(-1, 3)
    scene.lights[0].enabled = False
    ambient = render_image(scene, SIZE).reshape(-1, 3)
    scene.lights[0].enabled = True
    ray, position, normal, t, ng = _torus_pixels(scene)
    light = np.asarray(scene.lights[0].position, float)
    to_light = light - position
    n_dot_l = np.einsum("rk,rk->r", normal, to_light / np.linalg.norm(to_light, axis=1)[:, None])
    near = (n_dot_l > -t) & (n_dot_l < t * 0.98)    # the faceted silhouette lies in here
    assert near.sum() > 50
    assert np.abs(shadowed[ray][near] - ambient[ray][near]).max() < 1e-5


def test_gouraud_fades_at_the_vertices_too(gl_ctx):
    """Gouraud evaluates the equation at the corners: a face turned from the light has all
    three corners at N.L <= t, so its light term is 0 and the frame there is ambient."""
    from shadelab.raster.offscreen import render_image

    scene = torus_scene("render.shading=gouraud")
    shadowed = render_image(scene, SIZE).reshape(-1, 3)
    scene.lights[0].enabled = False
    ambient = render_image(scene, SIZE).reshape(-1, 3)
    scene.lights[0].enabled = True
    ray, position, normal, t, ng = _torus_pixels(scene)
    light = np.asarray(scene.lights[0].position, float)
    to_light = light - position
    n_dot_l = np.einsum("rk,rk->r", normal, to_light / np.linalg.norm(to_light, axis=1)[:, None])
    away = np.einsum("rk,rk->r", ng, to_light) <= 0.0      # faces turned from the light
    near = away & (n_dot_l > -t)
    assert near.sum() > 20
    assert np.abs(shadowed[ray][near] - ambient[ray][near]).max() < 1e-5
