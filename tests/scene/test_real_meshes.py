"""Real mesh files as users have them (issue 20, items 2-3): STL welding, zero-area triangles
dropped with a note, an OBJ's MTL (Kd, map_Kd), a triangle-counted bar; the shipped meshes
of presets/meshes (their licences are listed beside them)."""

from __future__ import annotations

import numpy as np
import pytest

from shadelab.cli import main
from shadelab.errors import ShadeLabError
from shadelab.geometry.mesh import object_mesh, read_mesh, scene_meshes, weld_vertices
from shadelab.geometry.normals import corner_normals
from shadelab.resources import presets_dir
from shadelab.scene.preset import load_preset

MESHES = presets_dir() / "meshes"


def _angles(mesh) -> np.ndarray:
    """Angle (degrees) between each corner normal and its face normal."""
    cos = np.einsum("fk,fck->fc", mesh.face_normals, mesh.corner_normals)
    return np.degrees(np.arccos(np.clip(cos, -1.0, 1.0)))


def test_shipped_meshes_are_small_and_licensed():
    text = (MESHES / "LICENSES").with_suffix(".md").read_text()  # beside the meshes
    for name in ("spot.obj", "spot_texture.png", "spot.mtl", "ant.stl", "airplane.ply"):
        assert (MESHES / name).stat().st_size < 1.5 * 2**20
        assert f"`{name}`" in text


def test_stl_is_welded_on_load():
    """ant.stl stores each of its 912 triangles' own corners (2736); welded, they are the 486
    vertices of the PLY it was written from, and every face uses 3 distinct ones."""
    import trimesh

    raw = trimesh.load(MESHES / "ant.stl", process=False)
    assert len(raw.vertices) == 3 * len(raw.faces) == 2736
    mesh = read_mesh("ant.stl", str(MESHES), "objects.0.path")
    assert len(mesh.vertices) == 486 and len(mesh.faces) == 912 and mesh.dropped == 0
    kept = read_mesh("ant.stl", str(MESHES), "objects.0.path", weld=False)
    assert len(kept.vertices) == 2736


def test_weld_false_keeps_the_stl_faceted():
    scene = load_preset("mesh-stl")
    ant = scene.objects[1]
    ant.normals = "angle"                                # one normal per vertex, no crease
    smooth = object_mesh(ant, 1, scene.base_dir)
    assert _angles(smooth).max() > 20.0                  # averaged normals bend at corners
    ant.weld = False
    faceted = object_mesh(ant, 1, scene.base_dir)
    assert len(faceted.vertices) == 3 * len(faceted.faces)
    assert _angles(faceted).max() < 1e-4                 # every corner keeps its face normal
                                                         # (arccos near 1: rounding ~1e-6)


def test_weld_tolerance_is_relative_to_the_mesh_size():
    """Two triangles sharing an edge, the shared corners 1e-9 apart (of a diagonal ~1.4) or
    1e-3 apart: merged at 1e-6 of the diagonal, kept apart above it; at any scale."""
    for scale in (1e-6, 1.0, 1e6):
        for gap, merged in ((1e-9, True), (1e-3, False)):
            v = np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0],
                          [1 + gap, 0, 0], [1, 1, 0], [0, 1 + gap, 0]], float) * scale
            f = np.array([[0, 1, 2], [3, 4, 5]])
            out, faces, _, places = weld_vertices(v, f)
            assert len(out) == (4 if merged else 6) and places is None
            assert faces.max() < len(out)


def test_uv_seams_stay_split_but_share_normals():
    """Spot (OBJ with uvs): welding keeps vertices that differ only in uv (the texture's
    seams) and gives them one place, so their corner normals agree across the seam."""
    scene = load_preset("mesh-spot")
    scene.objects[1].normals = "angle"                   # one normal per place, no crease
    spot = scene_meshes(scene)[1]
    loaded = read_mesh("spot.obj", str(MESHES), "objects.1.path")
    assert loaded.places is not None and loaded.places.max() + 1 < len(loaded.vertices)
    corner_place = loaded.places[loaded.faces].reshape(-1)
    normals = spot.corner_normals.reshape(-1, 3)
    for place in np.unique(corner_place)[:400]:
        here = normals[corner_place == place]
        assert np.abs(here - here[0]).max() < 1e-9


@pytest.mark.gl
def test_stl_phong_differs_from_flat(gl_ctx):
    """Welded, the STL's Phong image differs from its flat one and from the unwelded Phong
    (whose corner normals are its faces': faceted); flat shading is the same either way."""
    from shadelab.raster.offscreen import render_image

    scene = load_preset("mesh-stl")
    phong = render_image(scene, (96, 72), "phong").astype(np.float64)
    flat = render_image(scene, (96, 72), "flat").astype(np.float64)
    assert np.abs(phong - flat).max() > 0.1
    scene.objects[1].weld = False
    faceted = render_image(scene, (96, 72), "phong").astype(np.float64)
    flat_kept = render_image(scene, (96, 72), "flat").astype(np.float64)
    assert np.abs(phong - faceted).max() > 0.1
    assert np.abs(flat - flat_kept).max() < 1e-3


# ---------------------------------------------------------------- zero-area triangles

TWO_GOOD_ONE_FLAT = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 2 0 0\n" \
                    "f 1 2 3\nf 2 4 3\nf 1 2 5\n"


def _preset(tmp_path, mesh_name: str, extra: str = "", material: str = "") -> str:
    (tmp_path / "p.toml").write_text(
        'schema_version = 1\n[camera]\neye = [0.5, 0.5, 3.0]\ntarget = [0.5, 0.5, 0.0]\n'
        'fov_y = 30.0\n[[lights]]\nkind = "directional"\ndirection = [0.0, 0.0, -1.0]\n'
        f'[materials.m]\nka = 0.0\nkd = 1.0\n{material}'
        f'[[objects]]\nshape = "mesh"\nmaterial = "m"\npath = "{mesh_name}"\n{extra}')
    return str(tmp_path / "p.toml")


def test_zero_area_triangles_are_dropped_with_a_note(tmp_path, capsys):
    (tmp_path / "flat1.obj").write_text(TWO_GOOD_ONE_FLAT)
    path = _preset(tmp_path, "flat1.obj")
    assert main(["validate", path]) == 0
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "dropped 1 degenerate (zero-area) triangle of 3" in err
    meshes = scene_meshes(load_preset(path))
    assert len(meshes[0].faces) == 2 and np.all(meshes[0].areas > 0.49)


def test_a_mesh_with_no_triangle_left_is_refused(tmp_path, capsys):
    (tmp_path / "flat.obj").write_text("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\nf 1 3 2\n")
    assert main(["validate", _preset(tmp_path, "flat.obj")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert "only degenerate (zero-area) triangles (2 of them)" in err


# ---------------------------------------------------------------- an OBJ's material

QUAD = ("mtllib {mtl}\nusemtl {name}\nv 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\n"
        "vt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\nf 1/1 2/2 3/3\nf 1/1 3/3 4/4\n")


def _textured_quad(tmp_path, mtl_text: str) -> None:
    from PIL import Image

    image = Image.new("RGB", (2, 1))
    image.putpixel((0, 0), (255, 0, 0))   # left half red, right half green
    image.putpixel((1, 0), (0, 255, 0))
    image.save(tmp_path / "rg.png")
    (tmp_path / "q.mtl").write_text(mtl_text)
    (tmp_path / "q.obj").write_text(QUAD.format(mtl="q.mtl", name="paint"))


def test_map_kd_and_kd_become_the_material(tmp_path, capsys):
    _textured_quad(tmp_path, "newmtl paint\nKd 0.5 0.25 1.0\nNs 10\nmap_Kd rg.png\n")
    scene = load_preset(_preset(tmp_path, "q.obj"))
    material = scene.material_of(scene.objects[0])
    assert scene.objects[0].material == "m-q"
    assert material.texture == "rg.png" and material.texture_scale == 1.0
    assert material.Od == (0.5, 0.25, 1.0)
    assert scene.materials["m"].texture == ""               # the preset's own is untouched
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "ignored Ns" in err
    mesh = scene_meshes(scene)[0]                          # the file's own uvs
    np.testing.assert_allclose(mesh.uvs[:, 0], mesh.vertices[:, 0], atol=1e-12)


def test_the_preset_s_od_and_texture_win_over_the_mtl(tmp_path, capsys):
    _textured_quad(tmp_path, "newmtl paint\nKd 0.5 0.25 1.0\nmap_Kd rg.png\n")
    scene = load_preset(_preset(tmp_path, "q.obj", material='Od = [0.2, 0.2, 0.2]\n'
                                                          'texture = "checker"\n'))
    assert scene.objects[0].material == "m"
    err = capsys.readouterr().err
    assert "map_Kd (the preset sets a texture)" in err and "Kd (the preset sets Od)" in err


@pytest.mark.gl
def test_map_kd_colours_the_pixels(tmp_path, gl_ctx):
    """A quad facing the camera under a head-on light: kd = 1, Od = Kd = 1, so the left half
    shows the texture's red and the right half its green (linear 1.0, within GL_LINEAR's
    blend near the middle)."""
    from shadelab.raster.offscreen import render_image

    _textured_quad(tmp_path, "newmtl paint\nKd 1 1 1\nmap_Kd rg.png\n")
    scene = load_preset(_preset(tmp_path, "q.obj", extra='normals = "flat"\n'))
    image = render_image(scene, (64, 64), "flat").astype(np.float64)
    left, right = image[32, 22], image[32, 42]
    assert left[0] > 0.9 and left[1] < 0.1 and right[1] > 0.9 and right[0] < 0.1


def test_a_missing_map_kd_texture_is_one_line(tmp_path, capsys):
    (tmp_path / "q.mtl").write_text("newmtl paint\nmap_Kd gone.png\n")
    (tmp_path / "q.obj").write_text(QUAD.format(mtl="q.mtl", name="paint"))
    assert main(["validate", _preset(tmp_path, "q.obj")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err
    assert "map_Kd 'gone.png'" in err and "objects.0.path" in err


def test_an_unreadable_map_kd_image_is_one_line(tmp_path, capsys):
    (tmp_path / "q.mtl").write_text("newmtl paint\nmap_Kd rg.png\n")
    (tmp_path / "rg.png").write_bytes(b"not a png")
    (tmp_path / "q.obj").write_text(QUAD.format(mtl="q.mtl", name="paint"))
    assert main(["validate", _preset(tmp_path, "q.obj")]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "Traceback" not in err and "rg.png" in err


def test_shipped_spot_takes_its_texture_from_the_mtl():
    scene = load_preset("mesh-spot")
    material = scene.material_of(scene.objects[1])
    assert material.texture == "meshes/spot_texture.png" and material.Od == (1.0, 1.0, 1.0)


# ---------------------------------------------------------------- progress in triangles


@pytest.mark.parametrize("mode", ["crease", "angle", "flat"])
def test_normals_report_every_triangle_once(mode):
    import trimesh

    sphere = trimesh.creation.icosphere(subdivisions=3)
    counts: list[int] = []
    corner_normals(np.asarray(sphere.vertices), np.asarray(sphere.faces), mode,
                   progress=counts.append)
    assert sum(counts) == len(sphere.faces) == 1280 and min(counts) > 0


def test_a_large_mesh_gets_a_triangle_bar_on_a_terminal(monkeypatch):
    from shadelab import progress
    from shadelab.geometry import mesh

    assert mesh._triangle_bar(10**6, "x") is None             # not on a terminal
    monkeypatch.setattr(progress, "SHOW_STEPS", True)
    assert mesh._triangle_bar(10, "x") is None                # small: no bar
    done = mesh._triangle_bar(mesh.TRIANGLE_BAR_MIN, "normals")
    assert callable(done)
    done(mesh.TRIANGLE_BAR_MIN)


def test_read_mesh_refuses_with_shadelab_error(tmp_path):
    (tmp_path / "flat.obj").write_text("v 0 0 0\nv 1 0 0\nv 2 0 0\nf 1 2 3\n")
    with pytest.raises(ShadeLabError, match="nothing to draw"):
        read_mesh("flat.obj", str(tmp_path), "objects.0.path")
