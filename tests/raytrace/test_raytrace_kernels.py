"""The numba kernels are held to the numpy reference (shadelab.shading.reference.shade and the
numpy TraceContext path): 1e-9 relative on random inputs, whole images within 1e-9."""

from __future__ import annotations

import numpy as np
import pytest

from shadelab.raytrace.surface import TraceContext
from shadelab.raytrace.whitted import render_raytraced, trace_batch
from shadelab.scene.camera import primary_rays
from shadelab.scene.model import Light, Material
from shadelab.scene.preset import load_preset
from shadelab.shading import kernels as shading_kernels
from shadelab.shading import packing
from shadelab.shading.reference import normalize, shade


def _lights(rng) -> list[Light]:
    return [
        Light(kind="point", position=tuple(rng.normal(size=3) * 3), Ip=(1.0, 0.5, 0.2),
              attenuation="inverse_square"),
        Light(kind="directional", direction=tuple(rng.normal(size=3)), Ip=(0.3, 0.6, 0.9)),
        Light(kind="spot", position=(0.0, 4.0, 0.0), direction=(0.1, -1.0, 0.2),
              cone_angle=40.0, spot_exponent=3.0, attenuation="lecture", c1=0.5, c2=0.1,
              c3=0.01, Ip=(2.0, 2.0, 2.0)),
        Light(kind="point", position=(1.0, 1.0, 1.0), attenuation="lecture", c1=0.1, c2=0.0,
              c3=0.0),  # the min(., 1) clamp is active
    ]


@pytest.mark.parametrize("specular", ["phong", "blinn"])
def test_local_shade_matches_reference_shade(np_rng, specular):
    n = 500
    position = np_rng.normal(size=(n, 3))
    normal = normalize(np_rng.normal(size=(n, 3)))
    to_eye = normalize(np_rng.normal(size=(n, 3)))
    materials = [Material(ka=0.2, kd=0.7, ks=0.4, n=30.0, Od=(0.9, 0.4, 0.1),
                          Os=(1.0, 0.8, 0.6), emission=(0.1, 0.0, 0.2)),
                 Material(ka=0.0, kd=0.3, ks=0.9, n=0.0),   # n = 0: 1 inside the lobe
                 Material(ka=1.0, kd=0.0, ks=0.5, n=1000.0)]
    lights = _lights(np_rng)
    mat = np_rng.integers(0, len(materials), n)
    shadow = np_rng.random((len(lights), n))
    ia = np.array([0.1, 0.2, 0.3])
    got = shading_kernels.local_shade(position, normal, to_eye, mat,
                                      packing.material_table(materials),
                                      packing.light_table(lights), ia, specular == "blinn",
                                      shadow)
    for m, material in enumerate(materials):
        idx = np.flatnonzero(mat == m)
        expected = shade(position[idx], normal[idx], position[idx] + to_eye[idx], material,
                         lights, ia, specular, [s[idx] for s in shadow])
        np.testing.assert_allclose(got[idx], expected, rtol=1e-9, atol=1e-12)


@pytest.mark.parametrize("fresnel", [False, True])
def test_kernel_and_numpy_paths_give_the_same_radiance(fresnel):
    scene = load_preset("cornell-spheres")
    o, d = primary_rays(scene.camera, 24, 24)
    o, d = o.reshape(-1, 3), d.reshape(-1, 3)
    fast = trace_batch(TraceContext(scene, local="numba"), o, d, 5, fresnel)
    slow = trace_batch(TraceContext(scene, local="numpy"), o, d, 5, fresnel)
    np.testing.assert_allclose(fast, slow, rtol=1e-9, atol=1e-9)


def test_whitted_preset_images_agree():
    scene = load_preset("whitted")
    scene.render.specular = "blinn"
    a = render_raytraced(scene, (20, 16), depth=3)
    from shadelab.raytrace import whitted

    ctx = TraceContext(scene, local="numpy")
    b = None
    for step in whitted.iter_raytrace(scene, (20, 16), depth=3, ctx=ctx):
        b = step.image
    np.testing.assert_allclose(a, b, rtol=1e-6, atol=1e-7)


def test_kernels_called_first_in_a_fresh_process_run_from_numbas_cache():
    """The serial entry points that call other kernels (camera_rays, local_shade), each in a
    new process, twice (the second run loads the compiled code from numba's cache): a
    parallel kernel called from a cached serial one can crash there (numba issue 8578; a
    parallel camera_rays_into once segfaulted this way)."""
    import subprocess
    import sys

    script = (
        "import numpy as np\n"
        "from shadelab.raytrace import rays as R\n"
        "from shadelab.shading import kernels as K\n"
        "o, d = R.camera_rays(np.zeros(3), np.array([0, 0, 1.0]), np.array([1.0, 0, 0]),"
        " np.array([0, 1.0, 0]), 0.5, 8, 6, 0, 6, np.zeros((0, 0, 2)))\n"
        "assert o.shape == (48, 3) and abs(np.linalg.norm(d, axis=1) - 1).max() < 1e-12\n"
        "s = K.local_shade(np.ones((4, 3)), np.tile([0, 1.0, 0], (4, 1)),"
        " np.tile([0, 1.0, 0], (4, 1)), np.zeros(4, np.int64), np.ones((1, 13)),"
        " np.zeros((0, 16)), np.ones(3), False, np.zeros((0, 4)))\n"
        "assert s.shape == (4, 3)\n")
    for _ in range(2):
        run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True,
                             timeout=300)
        assert run.returncode == 0, run.stderr[-2000:]


def test_no_serial_kernel_calls_a_parallel_one():
    """numba issue 8578: a parallel kernel called from a cached serial njit function crashed
    a fresh process loading both from the cache (camera_rays once, local_shade until this
    test's time); parallel kernels are entered from Python only."""
    import ast
    from pathlib import Path

    import shadelab

    parallel, serial = set(), []
    for path in Path(shadelab.__file__).parent.rglob("*.py"):
        for node in ast.parse(path.read_text()).body:
            if not isinstance(node, ast.FunctionDef):
                continue
            jit = [ast.unparse(d) for d in node.decorator_list if "jit" in ast.unparse(d)]
            if jit:
                (parallel.add(node.name) if "parallel=True" in jit[0]
                 else serial.append((path.name, node)))
    assert {"hit_surfaces", "local_shade_into3"} <= parallel   # the scan sees the kernels
    calls = {(f, node.name): {ast.unparse(c.func).split(".")[-1] for c in ast.walk(node)
                              if isinstance(c, ast.Call)} & parallel
             for f, node in serial}
    assert {k: v for k, v in calls.items() if v} == {}
