"""Every task kind graded right and wrong, on both sides of its tolerance, against values
the lab computes (closed forms and parities with shadelab.probe)."""

from __future__ import annotations

import math

import numpy as np
import pytest

import shadelab
from shadelab.errors import ShadeLabError
from shadelab.exercises import load_exercise, regions
from shadelab.exercises.headless import api_render

SQUARES = ("patches = [[[0, 0, 0], [1, 0, 0], [1, 1, 0], [0, 1, 0]], "
           "[[0, 1, 1], [1, 1, 1], [1, 0, 1], [0, 0, 1]]]\n")


def one_task(write_exercise, body: str):
    exercise = load_exercise(write_exercise("[[tasks]]\nid = \"t\"\nquestion = \"?\"\n" + body))
    task = exercise.tasks[0]
    task.render = api_render
    return task


def assert_boundary(task, value: float, tol: float):
    """Inside the tolerance passes, outside fails, on both sides of the value."""
    for sign in (1.0, -1.0):
        assert task.grade(value + sign * tol * 0.999).passed
        assert task.grade(value + sign * tol).passed
        assert not task.grade(value + sign * (tol * 1.001 + 1e-12)).passed
    assert task.grade(None).verdict == "unanswered"


def test_f_att_at_a_distance_is_the_lectures_formula_and_its_clamp(write_exercise):
    task = one_task(write_exercise, 'kind = "number"\npreset = "lecture"\n'
                    'quantity = "f_att(d)"\ndistance = 5.0\ntolerance = 0.01\n')
    light = shadelab.load_preset("lecture").lights[0]
    closed = 1.0 / (light.c1 + light.c2 * 5.0 + light.c3 * 25.0)
    assert task.expected().value == pytest.approx(closed, rel=1e-12)
    assert_boundary(task, closed, 0.01)
    clamp = one_task(write_exercise, 'kind = "number"\npreset = "lecture"\n'
                     'set = ["lights.0.c1=0.25"]\nquantity = "f_att(d)"\ndistance = 2.0\n'
                     'tolerance = 0.0\n')
    assert clamp.expected().value == 1.0 and clamp.expected().detail["clamped"]
    assert clamp.grade(1.0).passed and not clamp.grade(1.0 + 1e-6).passed


@pytest.mark.parametrize("quantity", ["N.L", "R.V", "N.H", "diffuse", "I"])
def test_probe_quantities_match_the_probe_and_the_equation(write_exercise, quantity):
    task = one_task(write_exercise, f'kind = "number"\npreset = "lecture"\n'
                    f'set = ["render.shadows=none"]\nquantity = "{quantity}"\n'
                    'pixel = [30, 25]\nchannel = "b"\ntolerance = 0.05\n')
    scene = shadelab.load_preset("lecture", {"render.shadows": "none"})
    spec = {"R.V": "phong", "N.H": "blinn"}.get(quantity)
    p = shadelab.probe(scene, (30, 25), (64, 48), specular=spec)
    n, light = np.array(p["normal"]), p["lights"][0]
    L = np.array(light["to_light"])
    if quantity == "N.L":
        want = max(n @ L, 0.0)
    elif quantity == "R.V":
        R = 2 * n * (n @ L) - L   # the lecture's R, from the probe's N and L
        want = max(R @ np.array(p["to_eye"]), 0.0)
    elif quantity == "N.H":
        H = L + np.array(p["to_eye"])
        want = max(n @ (H / np.linalg.norm(H)), 0.0)
    elif quantity == "diffuse":   # S f_att Ip kd Od (N.L), blue
        mat = scene.materials[p["material"]]
        want = light["shadow"] * light["f_att"] * light["spot"] * scene.lights[0].Ip[2] \
            * mat.kd * mat.Od[2] * max(n @ L, 0.0)
    else:
        want = p["reference"][2]
    value = task.expected().value
    assert value == pytest.approx(want, abs=1e-9)
    assert_boundary(task, value, 0.05)


def test_a_background_pixel_is_one_line_naming_the_task_and_key(write_exercise):
    task = one_task(write_exercise, 'kind = "number"\npreset = "whitted"\nquantity = "N.L"\n'
                    'pixel = [0, 0]\ntolerance = 0.1\n')
    with pytest.raises(ShadeLabError, match=r"tasks\[0\] \('t'\): pixel: \[0, 0\] shows the "
                                            "background"):
        task.expected()


def test_form_factor_of_parallel_squares_is_howells_closed_form(write_exercise):
    task = one_task(write_exercise, 'kind = "number"\npreset = "lecture"\nquantity = "F"\n'
                    + SQUARES + "tolerance = 0.01\n")
    value = task.expected().value
    assert value == pytest.approx(0.19982, abs=0.003)          # Howell C-11
    assert task.expected().detail["reverse"] == pytest.approx(value, rel=1e-9)  # equal areas
    assert_boundary(task, value, 0.01)


def test_first_shot_of_progressive_refinement_is_rho_E_F(write_exercise):
    task = one_task(write_exercise, 'kind = "number"\npreset = "lecture"\nquantity = "B"\n'
                    + SQUARES + 'rho = [0.5, 0.4]\nemission = [2.0, 0.0]\nshots = 1\n'
                    'patch = 1\ntolerance = 0.001\n')
    F = one_task(write_exercise, 'kind = "number"\npreset = "lecture"\nquantity = "F"\n'
                 + SQUARES + "tolerance = 0.01\n").expected().value
    value = task.expected().value
    assert value == pytest.approx(0.4 * math.pi * 2.0 * F, rel=1e-9)  # E = pi Le, A1 = A2
    assert task.expected().detail["shooters"] == [0]
    assert_boundary(task, value, 0.001)


def test_ray_tree_counts_are_the_tracers_tree(write_exercise):
    body = ('kind = "number"\npreset = "whitted"\nquantity = "rays"\npixel = [43, 24]\n'
            'tolerance = 0\ndepth = {d}\nrays = "{k}"\n')
    zero = one_task(write_exercise, body.format(d=0, k="all")).expected()
    lights = len(shadelab.load_preset("whitted").active_lights())
    assert zero.value == 1 + lights          # the primary ray and one shadow ray per light
    two = one_task(write_exercise, body.format(d=2, k="all"))
    counts = two.expected().detail["counts"]
    assert counts["all"] == sum(v for k, v in counts.items() if k != "all")
    assert counts["primary"] == 1 and counts["all"] > zero.value
    assert two.grade(counts["all"]).passed and not two.grade(counts["all"] + 1).passed
    assert not two.grade(counts["all"] - 1).passed


CHOICE = """kind = "choice"
preset = "sphere-shading"
correct = "Gouraud"
[[tasks.options]]
label = "flat"
shading = "flat"
[[tasks.options]]
label = "Gouraud"
shading = "gouraud"
[[tasks.options]]
label = "Phong"
shading = "phong"
"""


def test_which_picture_grades_the_letter_of_the_right_option(write_exercise):
    task = one_task(write_exercise, CHOICE)
    expected = task.expected()
    assert expected.detail["labels"][expected.value] == "Gouraud"
    for letter in "ABC":
        assert task.grade(letter).passed == (letter == expected.value)
        assert task.grade(letter.lower()).passed == (letter == expected.value)
    wrong = next(letter for letter in "ABC" if letter != expected.value)
    assert not task.grade(wrong).passed
    reveal = task.reveal(task.grade(wrong))
    assert "|yours - right|" in reveal.images and len(reveal.images) == 4


def test_which_picture_refuses_options_that_render_the_same(write_exercise):
    task = one_task(write_exercise, CHOICE.replace('shading = "phong"', 'shading = "flat"'))
    with pytest.raises(ShadeLabError, match=r"tasks\[0\] \('t'\): options: "
                                            "'(flat|Phong)' and '(flat|Phong)' render the same"):
        task.expected()


def test_match_the_target_by_rmse_on_both_sides_of_the_threshold(write_exercise):
    body = ('kind = "match"\npreset = "lecture"\nset = ["render.shadows=none"]\n'
            'params = ["materials.plastic.kd"]\ntarget = [0.6]\nthreshold = {t}\n')
    task = one_task(write_exercise, body.format(t=0.01))
    assert task.grade([0.6]).detail["rmse"] == 0.0 and task.grade([0.6]).passed
    scene = shadelab.load_preset("lecture", {"render.shadows": "none"})
    a = shadelab.render(shadelab.load_preset("lecture", {"render.shadows": "none",
                                                         "materials.plastic.kd": 0.5}),
                        (64, 48)).array
    b = shadelab.render(shadelab.load_preset("lecture", {"render.shadows": "none",
                                                         "materials.plastic.kd": 0.6}),
                        (64, 48)).array
    err = float(np.sqrt(np.mean((a.astype(float) - b.astype(float)) ** 2)))
    assert err > 0 and scene.materials["plastic"].kd != 0.5
    result = task.grade([0.5])
    assert result.detail["rmse"] == pytest.approx(err, rel=1e-6)
    assert result.detail["distance"] == {"materials.plastic.kd": pytest.approx(0.1)}
    assert one_task(write_exercise, body.format(t=err * 1.0001)).grade([0.5]).passed
    assert not one_task(write_exercise, body.format(t=err * 0.999)).grade([0.5]).passed
    reveal = task.reveal(result)
    assert set(reveal.images) == {"target", "yours", "|yours - target|"}


@pytest.mark.parametrize("region", ["specular", "shadow", "mach"])
def test_find_the_pixel_by_region_on_both_sides_of_the_tolerance(write_exercise, region):
    preset = {"specular": "lecture", "shadow": "shadows", "mach": "fail-mach-bands"}[region]
    extra = 'set = ["render.shadows=none"]\n' if region == "specular" else ""
    task = one_task(write_exercise, f'kind = "pixel"\npreset = "{preset}"\n{extra}'
                    f'region = "{region}"\ntolerance = 2\n')
    expected = task.expected()
    mask = expected.detail["mask"]
    assert mask.any() and not mask.all()
    assert task.grade(list(expected.value)).passed
    distances = np.array([[regions.distance_to(mask, (x, y)) for x in range(64)]
                          for y in range(48)])
    for d, ok in ((2, True), (3, False)):
        ys, xs = np.nonzero(distances == d)
        assert len(xs), f"no pixel {d} px from the region"
        assert task.grade((int(xs[0]), int(ys[0]))).passed == ok
    assert "region" in task.reveal().images


def test_the_specular_region_is_where_the_specular_term_peaks():
    full = np.zeros((4, 5, 3))
    full[1, 2] = 1.0
    full[2, 2] = 0.4
    mask = regions.specular_region(full, np.zeros_like(full), 0.5)
    assert mask.sum() == 1 and mask[1, 2]
    assert regions.distance_to(mask, (4, 3)) == 2.0
    assert regions.rmse(full, np.zeros_like(full)) == pytest.approx(
        math.sqrt((3 * 1.0 + 3 * 0.16) / 60))
