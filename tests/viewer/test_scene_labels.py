"""Labels in the scene (issue 22, item 3): a figure's values under its objects, names on
demand, probe arrows a fixed share of the view with their heads inside it, and every shipped
figure inside the frame at 1024x768 (docked panels and presenter)."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest

from shadelab.geometry.mesh import scene_meshes
from shadelab.lab import labels, overlays
from shadelab.lab.lesson import load_lesson
from shadelab.lab.probe import probe
from shadelab.scene import load_preset
from shadelab.scene.camera import tan_half_fov_y

PRESETS = sorted(p.stem for p in (Path(__file__).resolve().parents[2] / "presets").glob(
    "*.toml"))
# The viewport's width / height at a 1024x768 window: docked panels (normal and presenter
# fonts: about 536 x 727, measured) up to the presenter's viewport alone (Tab: 1024 wide over
# the caption band, about 1.45); sampled densely with a margin on both sides.
ASPECTS_1024 = np.linspace(0.70, 1.50, 17)
# The eye is inside this slab on purpose (the z-pass failure it shows).
EYE_INSIDE = {"fail-zpass-eye-inside"}


def _stage(scene, index: int) -> bool:
    """A floor, wall or backdrop: a flat opaque surface (plane, quad) the figure stands on or
    in front of, larger than the frame by design. Transparent panes are figures."""
    obj = scene.objects[index]
    return obj.shape in ("plane", "quad") and scene.materials[obj.material].kt == 0.0


def test_a_figure_is_labelled_with_the_coefficients_that_vary():
    assert list(labels.figure_values(load_preset("kd-grid")).values()) == [
        "kd = 0", "kd = 0.25", "kd = 0.5", "kd = 0.75", "kd = 1"]
    assert list(labels.figure_values(load_preset("ka-grid")).values()) == [
        "ka = 0", "ka = 0.25", "ka = 0.5", "ka = 0.75", "ka = 1"]
    ks_n = load_preset("ks-n-grid")
    values = labels.figure_values(ks_n)
    assert len(values) == len(ks_n.objects) == 12
    for i, obj in enumerate(ks_n.objects):
        m = ks_n.materials[obj.material]
        assert values[i] == f"ks = {m.ks:.3g}\nn = {m.n:.3g}"
    panes = labels.figure_values(load_preset("transparency"))
    assert panes == {2: "blue pane (interpolated)\nkt = 0.6",
                     3: "green pane (filtered)\nkt = 0.9",
                     4: "smoke pane (interpolated)\nkt = 0.75"}
    glass = labels.figure_values(load_preset("cornell-spheres"))
    assert list(glass.values()) == ["glass_sphere\ninterpolated, kt = 1"]
    assert labels.figure_values(load_preset("lecture")) == {}   # its materials differ in Od
    names = labels.object_names(load_preset("kd-grid"))
    assert names[0] == "kd_0.0 (kd0)" and len(names) == 5


def test_labels_sit_centred_under_their_objects():
    scene = load_preset("kd-grid")
    size = (536, 727)
    meshes = scene_meshes(scene)
    placed = labels.place_labels(scene, meshes, size, labels.figure_values(scene), _measure)
    assert [p.object_index for p in placed] == [0, 1, 2, 3, 4]
    cam = scene.camera
    aspect = size[0] / size[1]
    t = tan_half_fov_y(cam, aspect)
    assert t == pytest.approx(math.tan(math.radians(15.0)) * 1.4 / aspect)   # fit_aspect 1.4
    for p, obj in zip(placed, scene.objects, strict=True):
        # a pinhole image of the sphere's centre: x = W/2 (1 + X / (Z t aspect))
        x_centre = 0.5 * size[0] * (1.0 + obj.translate[0] / (6.0 * t * aspect))
        assert p.anchor[0] == pytest.approx(x_centre, abs=1.0)   # sphere symmetric about x
        box = labels.screen_box(scene, meshes[p.object_index], size)
        assert p.anchor[1] == pytest.approx(box[3] + labels.LABEL_GAP)
        assert 0 <= box[0] and box[2] <= size[0]
    # text near the bottom edge moves up into the viewport
    low = labels.place_labels(scene, meshes, (536, 40), {2: "kd = 0.5"}, _measure)
    assert labels.screen_box(scene, meshes[2], (536, 40))[3] + labels.LABEL_GAP > 40 - 27.0
    assert low[0].anchor[1] == pytest.approx(40 - 27.0)


def _measure(text: str) -> tuple[float, float]:
    """The presenter font's plates (1.8 x): about 10 px a character, 27 px a line."""
    lines = text.split("\n")
    return 10.0 * max(len(t) for t in lines), 27.0 * len(lines)


@pytest.mark.parametrize("name", ["kd-grid", "ka-grid", "ks-n-grid", "transparency"])
@pytest.mark.parametrize("size", [(536, 727), (1024, 640), (1024, 727)])
def test_labels_overlap_neither_each_other_nor_a_figure(name, size):
    scene = load_preset(name)
    meshes = scene_meshes(scene)
    names = labels.object_names(scene)
    with_names = {i: names[i] + ("\n" + v if v else "") for i, v in
                  (labels.figure_values(scene) | {0: ""}).items()}
    for texts in (labels.figure_values(scene), with_names):
        placed = labels.place_labels(scene, meshes, size, texts, _measure)
        assert len(placed) == len(texts)
        boxes = [labels.label_box(p, _measure) for p in placed]
        for k, a in enumerate(boxes):
            assert 0 <= a[0] and a[2] <= size[0] and 0 <= a[1] and a[3] <= size[1], placed[k]
            for b in boxes[k + 1:]:
                assert not labels._overlap(a, b), (placed[k].text, b)
    placed = labels.place_labels(scene, meshes, size, labels.figure_values(scene), _measure)
    boxes = [labels.label_box(p, _measure) for p in placed]
    if name != "transparency":     # (a pane's label may lie over the panes behind it)
        for mesh in meshes:
            shape = labels.screen_box(scene, mesh, size)
            for p, box in zip(placed, boxes, strict=True):
                assert not labels._overlap(shape, box), (p.text, scene.objects[mesh.index].name)


@pytest.mark.parametrize("name", PRESETS)
def test_every_figure_of_every_preset_fits_the_frame_at_1024x768(name):
    if name in EYE_INSIDE:
        pytest.skip("the eye sits inside the slab: the failure this preset shows")
    scene = load_preset(name)
    meshes = scene_meshes(scene)
    out = {}
    for aspect in ASPECTS_1024:
        for index, reach in labels.frame_overflow(scene, meshes, aspect).items():
            if not _stage(scene, index) and reach > 1.0:
                out[scene.objects[index].name or index] = round(float(aspect), 2)
    assert out == {}, f"{name}: objects leave the frame at these aspects: {out}"


def test_kd_grid_lost_its_outer_spheres_without_its_fit_aspect():
    scene = load_preset("kd-grid")
    scene.camera.fit_aspect = 1.0        # what it was: 536 x 727 cut kd = 0 and kd = 1
    reach = labels.frame_overflow(scene, scene_meshes(scene), 536 / 727)
    assert reach[0] > 1.2 and reach[4] > 1.2 and reach[2] < 1.0


def test_kd_grid_zero_sphere_does_not_sit_on_black():
    scene = load_preset("kd-grid")
    assert scene.materials["kd0"].kd == 0.0 and tuple(scene.Ia) == (0.0, 0.0, 0.0)
    assert min(scene.render.background) >= 0.03      # sRGB >= 48 of 255 around a black disc


def _probe(name, pixel, size):
    scene = load_preset(name)
    result = probe(scene, size, pixel)
    assert result is not None
    return scene, result


def test_probe_arrows_are_a_fixed_share_of_the_view_whatever_the_scene_size():
    size = (536, 727)
    scene, result = _probe("kd-grid", (268, 330), size)
    aspect = size[0] / size[1]
    specs = overlays.probe_arrow_specs(result, scene.camera, aspect)
    assert [s.name for s in specs] == ["N", "V", "L", "R"]
    forward = -np.asarray(scene.camera.eye) / np.linalg.norm(scene.camera.eye)
    depth = float(np.dot(result.point - np.asarray(scene.camera.eye), forward))
    full = overlays.ARROW_VIEW_FRACTION * 2.0 * depth * tan_half_fov_y(scene.camera, aspect)
    assert specs[0].length == pytest.approx(full)            # N, well inside the frame
    assert specs[3].length == pytest.approx(0.8 * full)      # R a little shorter
    x0, y0 = labels.to_pixels(scene, size, result.point)
    x1, y1 = labels.to_pixels(scene, size, specs[0].tip)
    assert math.hypot(x1 - x0, y1 - y0) <= overlays.ARROW_VIEW_FRACTION * size[1] * 1.001
    # the scene ten times larger, seen from ten times as far: the same arrows on screen
    big = load_preset("kd-grid")
    for obj in big.objects:
        obj.translate = tuple(10.0 * c for c in obj.translate)
        obj.radius *= 10.0
    big.camera.eye = tuple(10.0 * c for c in big.camera.eye)
    big.lights[0].position = tuple(10.0 * c for c in big.lights[0].position)
    big_result = probe(big, size, (268, 330))
    big_specs = overlays.probe_arrow_specs(big_result, big.camera, aspect)
    for a, b in zip(specs, big_specs, strict=True):
        assert b.length == pytest.approx(10.0 * a.length, rel=1e-3)
        np.testing.assert_allclose(labels.to_pixels(big, size, b.tip),
                                   labels.to_pixels(scene, size, a.tip), atol=0.05)


def test_probe_arrow_heads_stay_inside_the_viewport():
    size = (536, 727)
    aspect = size[0] / size[1]
    for pixel, limit in (((40, 400), 1.0 - overlays.ARROW_MARGIN),   # inside the margin
                         ((3, 400), 1.0)):                           # in it: the frame's edge
        scene, result = _probe("lecture", pixel, size)   # a floor point by the left edge
        specs = overlays.probe_arrow_specs(result, scene.camera, aspect)
        full = overlays.ARROW_VIEW_FRACTION * 2.0 * float(np.dot(
            result.point - np.asarray(scene.camera.eye), _forward(scene))) * tan_half_fov_y(
            scene.camera, aspect)
        shortened = []
        for spec in specs:
            x, y = labels.to_pixels(scene, size, spec.tip)
            ndc = (2 * x / size[0] - 1, 1 - 2 * y / size[1])
            assert max(abs(ndc[0]), abs(ndc[1])) <= limit + 1e-6, (pixel, spec.name)
            wanted = full * (0.8 if spec.name[0] in "RH" else 1.0)
            if spec.length < 0.99 * wanted:
                shortened.append(spec.name)
                assert max(abs(ndc[0]), abs(ndc[1])) == pytest.approx(limit, abs=1e-3)
        assert shortened, pixel                 # the ones leaning out were cut at the limit
    assert overlays.arrow_lines(specs).shape == (len(specs) * 10, 6)


def _forward(scene):
    d = np.subtract(scene.camera.target, scene.camera.eye)
    return d / np.linalg.norm(d)


def test_the_normals_step_draws_what_its_caption_says():
    step = load_lesson("phong-to-radiosity").steps[0]
    assert step.title.startswith("Normals")
    assert {"normals", "face_normals", "normal_diff"} <= set(step.show)
    scene = load_preset(step.preset)
    # the caption's vertex rule is the plain average, and that is the rule drawn
    assert "Nv = sum_i Ni / |sum_i Ni|" in step.caption
    assert {o.normals for o in scene.objects} == {"average"}
    # the heat map's other rule (area weighting, the default pair) is named in the caption
    from shadelab.lab.state import ViewState

    assert ViewState().normal_diff_modes == ("average", "area")
    assert "A_i Ni" in step.caption and "area" in step.caption
