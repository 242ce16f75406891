"""Point, spot and directional lights in radiosity (shadelab.radiosity.direct): closed forms.

A lecture light of intensity Ip puts the irradiance H = S f_att spot pi Ip cos(theta) on a
patch, which reflects E_direct = rho H (B = pi L, ARCHITECTURE.md §2), so the radiance
E_direct / pi is the raster's diffuse term S f_att Ip kd Od (N.L).

* one small patch (1 cm, 2-3 m from the light): rho pi Ip cos / d^2 (inverse square) and
  rho pi Ip cos min(1/(c1 + c2 d + c3 d^2), 1) (lecture) within 1e-4 relative (the patch's
  five samples against its centre: second order in 1 cm / 2 m);
* a spot: a patch inside the cone gets rho pi Ip cos f_att (cos phi)^e, one outside nothing;
* a directional light: rho pi Ip cos everywhere, nothing under an occluder (shadow rays);
* parity: on a plain lambertian floor the radiosity solution's radiance equals the numpy
  reference of the raster's diffuse term (shade() with ka = ks = 0) at the same sample
  points to 1e-9, and at the patch centres to 2 %;
* a scene lit only by a point light solves, and the solution says what the light put in.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from shadelab.errors import ShadeLabError
from shadelab.radiosity import direct
from shadelab.radiosity.patches import uniform_patches
from shadelab.radiosity.solution import check_scene, solve_scene
from shadelab.scene.preset import scene_from_dict
from shadelab.shading.reference import shade

RHO = np.array([0.6, 0.5, 0.3])  # kd = 1, Od = RHO
IP = np.array([1.5, 1.0, 0.5])


def _quad(name, center, half, material="white"):
    x, y, z = center
    return {"name": name, "shape": "quad", "material": material, "normals": "flat",
            "vertices": [[x - half, y, z + half], [x + half, y, z + half],
                         [x + half, y, z - half], [x - half, y, z - half]]}  # normal +y


def _scene(lights, objects):
    raw = {
        "schema_version": 1, "Ia": [0, 0, 0],
        "camera": {"eye": [0.0, 3.0, 4.0], "target": [0.0, 0.0, 0.0], "fov_y": 60.0},
        "lights": lights,
        "materials": {"white": {"ka": 0.0, "kd": 1.0, "ks": 0.0, "Od": list(RHO)}},
        "objects": objects,
    }
    return scene_from_dict(raw, "<test>")


def _one_patch(scene):
    patches = uniform_patches(scene, len(scene.objects))
    E, power = direct.direct_radiosity(scene, patches)
    return patches, E, power


@pytest.mark.parametrize("mode", ["inverse_square", "lecture", "none"])
def test_point_light_over_a_small_patch(mode):
    position = np.array([1.0, 2.0, 0.5])
    light = {"name": "key", "kind": "point", "position": list(position), "Ip": list(IP),
             "attenuation": mode, "c1": 1.0, "c2": 0.3, "c3": 0.2}
    scene = _scene([light], [_quad("patch", (0.0, 0.0, 0.0), 0.005)])
    patches, E, power = _one_patch(scene)
    assert len(patches) == 1
    d = float(np.linalg.norm(position))
    cos = position[1] / d
    f_att = {"inverse_square": 1.0 / d**2, "none": 1.0,
             "lecture": min(1.0 / (1.0 + 0.3 * d + 0.2 * d * d), 1.0)}[mode]
    expected = RHO * math.pi * IP * cos * f_att
    np.testing.assert_allclose(E[0], expected, rtol=1e-4)
    area = 0.01 ** 2
    assert power["key"] == pytest.approx(math.pi * IP.mean() * cos * f_att * area, rel=1e-4)


def test_spot_cone_lights_inside_and_nothing_outside():
    position = np.array([0.0, 2.0, 0.0])
    spot = {"name": "spot", "kind": "spot", "position": list(position), "Ip": list(IP),
            "direction": [0.0, -1.0, 0.0], "cone_angle": 20.0, "spot_exponent": 3.0,
            "attenuation": "inverse_square"}
    inside, outside = (0.3, 0.0, 0.0), (1.5, 0.0, 0.0)  # 8.5 and 36.9 degrees off the axis
    scene = _scene([spot], [_quad("in", inside, 0.005), _quad("out", outside, 0.005)])
    patches, E, _ = _one_patch(scene)
    assert len(patches) == 2
    k_in = int(np.argmin(np.abs(patches.centers[:, 0] - inside[0])))
    delta = position - np.asarray(inside)
    d = float(np.linalg.norm(delta))
    cos = delta[1] / d  # N.L, and also cos phi to the spot's axis (straight down)
    expected = RHO * math.pi * IP * cos / d**2 * cos**3
    np.testing.assert_allclose(E[k_in], expected, rtol=1e-4)
    np.testing.assert_array_equal(E[1 - k_in], 0.0)


def test_directional_light_and_its_shadow():
    to_light = np.array([1.0, 2.0, 0.0]) / math.sqrt(5.0)
    sun = {"name": "sun", "kind": "directional", "direction": list(-to_light), "Ip": list(IP),
           "attenuation": "inverse_square"}  # no f_att at infinity
    lit, shaded = (-1.0, 0.0, 0.0), (1.0, 0.0, 0.0)
    # a 0.4 m blocker 1 m above the shaded patch, shifted towards the light by 0.5 m
    blocker = _quad("blocker", (1.5, 1.0, 0.0), 0.2)
    blocker["vertices"] = blocker["vertices"][::-1]  # facing down: it does not matter
    scene = _scene([sun], [_quad("lit", lit, 0.005), _quad("shaded", shaded, 0.005), blocker])
    patches, E, _ = _one_patch(scene)
    small = np.flatnonzero(patches.areas < 1e-3)
    assert len(small) == 2
    k_lit = small[np.argmin(patches.centers[small, 0])]
    k_shaded = small[np.argmax(patches.centers[small, 0])]
    np.testing.assert_allclose(E[k_lit], RHO * math.pi * IP * to_light[1], rtol=1e-9)
    np.testing.assert_array_equal(E[k_shaded], 0.0)


def test_lambertian_floor_matches_the_raster_diffuse_term():
    """Radiosity's first bounce against the raster's equation on a floor (nothing else: F = 0,
    so B = E_direct). Tolerances: 1e-9 at the same sample points (same formula), 2 % at the
    patch centres (0.5 m patches, the light 1.5 m up: the five-sample mean's curvature)."""
    light = {"name": "key", "kind": "point", "position": [0.4, 1.5, -0.3], "Ip": list(IP),
             "attenuation": "lecture", "c1": 1.0, "c2": 0.02, "c3": 0.004}
    scene = _scene([light], [_quad("floor", (0.0, 0.0, 0.0), 2.0)])
    solution = solve_scene(scene, patches=64, solver="direct", adaptive=False)
    patches = solution.patches
    assert len(patches) == 64
    material = scene.materials["white"]
    eye = np.asarray(scene.camera.eye, float)
    points = direct.sample_points(patches)
    normals = np.broadcast_to(patches.normals[:, None, :], points.shape)
    raster = shade(points, normals, eye, material, scene.lights, np.zeros(3)).mean(axis=1)
    np.testing.assert_allclose(solution.radiance, raster, rtol=1e-9)
    at_centres = shade(patches.centers, patches.normals, eye, material, scene.lights,
                       np.zeros(3))
    # measured: 1.24 % at the patch under the light
    np.testing.assert_allclose(solution.radiance, at_centres, rtol=2e-2)


def test_a_scene_lit_by_a_point_light_only_solves_and_reports_it():
    light = {"name": "key", "kind": "point", "position": [0.0, 1.0, 0.0], "Ip": list(IP),
             "attenuation": "none"}
    floor = _quad("floor", (0.0, 0.0, 0.0), 1.0)
    wall = {"name": "wall", "shape": "quad", "material": "white", "normals": "flat",
            "vertices": [[-1, 0, -1], [1, 0, -1], [1, 2, -1], [-1, 2, -1]]}
    scene = _scene([light], [floor, wall])
    check_scene(scene)
    solution = solve_scene(scene, patches=50, adaptive=False)
    assert solution.B.max() > 0.0
    assert solution.stats["light_power"]["key"] > 0.0
    assert "key" in solution.stats["light"] and solution.stats["emitted_power"] == 0.0
    # the wall, facing +z, receives the floor's bounce as well as the direct light
    direct_only, _ = direct.direct_radiosity(scene, solution.patches)
    assert np.all(solution.B >= direct_only - 1e-12)
    assert solution.B.sum() > direct_only.sum()


def test_no_emitter_and_no_light_is_refused():
    light = {"name": "key", "kind": "point", "enabled": False}
    scene = _scene([light], [_quad("floor", (0.0, 0.0, 0.0), 1.0)])
    with pytest.raises(ShadeLabError, match="no light is on"):
        check_scene(scene)


def test_viewport_job_shoots_the_light_first():
    from shadelab.pipelines.radiosity import pipeline_radiosity

    light = {"name": "key", "kind": "point", "position": [0.0, 1.0, 0.0], "Ip": list(IP),
             "attenuation": "none"}
    scene = _scene([light], [_quad("floor", (0.0, 0.0, 0.0), 1.0)])
    scene.radiosity.patches = 16
    *_, last = pipeline_radiosity(scene)
    assert last.stats["done"] and "key" in last.message
    _, power = direct.direct_radiosity(scene, uniform_patches(scene, 16))
    assert last.stats["light_power"]["key"] == pytest.approx(power["key"], rel=1e-12)
    assert last.stats["soup"][:, 3:].max() > 0.0


@pytest.mark.gl
@pytest.mark.slow
def test_cli_radiosity_of_the_lecture_preset(gl_ctx, tmp_path, capsys):
    from shadelab.cli import main

    out = tmp_path / "x.png"
    lighter = [a for i in (2, 3, 4) for a in ("--set", f"objects.{i}.subdivisions=1")]
    assert main(["radiosity", "lecture", "-o", str(out), "--size", "32x24", "--patches", "80",
                 "--uniform", *lighter]) == 0
    assert out.is_file()
    assert "power onto the patches: key" in capsys.readouterr().out


@pytest.mark.parametrize("solver", ["direct", "progressive"])
def test_both_drivers_give_the_same_solution(solver):
    """run() (uniform) and the viewer's shot-by-shot job share one driver
    (solution.solver_steps): same patches, same E, same solver, so the same display
    triangles to 1e-6 (float32 soups), progressive down to the same tolerance."""
    from shadelab.pipelines import radiosity as pipeline
    from shadelab.pipelines.radiosity import RadiosityPipeline, pipeline_radiosity, soup

    pipeline._RADIOSITY_CACHE.clear()  # matrix() fills rows by reciprocity, row(i) casts them

    light = {"name": "key", "kind": "point", "position": [0.2, 1.5, 0.1], "Ip": list(IP),
             "attenuation": "none"}
    wall = {"name": "wall", "shape": "quad", "material": "white", "normals": "flat",
            "vertices": [[-1, 0, -1], [1, 0, -1], [1, 2, -1], [-1, 2, -1]]}
    scene = _scene([light], [_quad("floor", (0.0, 0.0, 0.0), 1.0), wall])
    scene.radiosity.patches, scene.radiosity.solver = 32, solver
    scene.radiosity.tolerance = 1e-9
    *_, last = RadiosityPipeline().run(scene, adaptive=False)
    solution = last.stats["solution"]
    *_, view = pipeline_radiosity(scene)
    np.testing.assert_allclose(view.stats["soup"], soup(solution.display_meshes()), atol=1e-6)
    assert view.stats["light"] == solution.stats["light"]
