"""Auto quality: the cheapest setting on the measured front within an error budget."""

from __future__ import annotations

import pytest

from shadelab.cli import main
from shadelab.errors import ShadeLabError
from shadelab.studies.autoquality import FrontPoint, choose_setting, pareto_front

FRONT = [FrontPoint({"level": k}, cost=20 * 4 ** k, error=0.1 / 3.5 ** k) for k in range(6)]


def _check_choice(points, budget):
    """The chosen point meets the budget and the next cheaper front point does not."""
    front = pareto_front(points)
    choice = choose_setting(points, budget)
    assert choice.met and choice.point.error <= budget
    i = front.index(choice.point)
    if i > 0:
        assert front[i - 1].error > budget and front[i - 1].cost < choice.point.cost
    return choice


@pytest.mark.parametrize("budget", [0.2, 0.05, 0.01, 1e-3, 3e-4])
def test01_synthetic_front(budget):
    choice = _check_choice(FRONT, budget)
    expected = min(k for k in range(6) if 0.1 / 3.5 ** k <= budget)
    assert choice.point.setting == {"level": expected}


def test02_dominated_points_are_dropped():
    slow_and_bad = FrontPoint({"level": 9}, cost=1e6, error=1.0)
    front = pareto_front([*FRONT, slow_and_bad])
    assert slow_and_bad not in front
    assert [p.cost for p in front] == sorted(p.cost for p in front)
    assert all(a.error > b.error for a, b in zip(front, front[1:], strict=False))


def test03_unreachable_budget_returns_best_unmet():
    choice = choose_setting(FRONT, 1e-9)
    assert not choice.met and choice.point.setting == {"level": 5}


@pytest.mark.parametrize("budget", [0.0, -1.0, float("nan"), float("inf")])
def test04_bad_budget_is_an_error(budget):
    with pytest.raises(ShadeLabError):
        choose_setting(FRONT, budget)
    with pytest.raises(ShadeLabError):
        choose_setting([], 0.01)


@pytest.mark.gl
@pytest.mark.parametrize("shading", ["flat", "gouraud", "phong"])
def test05_measured_tessellation_front(gl_ctx, shading):
    from shadelab.studies.autoquality import front_from_rows
    from shadelab.studies.shading_study import COLUMNS, measure_sphere, study_scene

    rows = measure_sphere(study_scene(), 0, shading, (48, 48), repeats=1)
    records = [dict(zip(COLUMNS, r, strict=True)) for r in rows]
    points = front_from_rows(records, ("level",), "triangles")
    front = pareto_front(points)
    assert len(front) >= 2  # finer levels are measurably better
    # every error on the measured front is a reachable budget; the choice meets it exactly
    for point in front:
        choice = _check_choice(points, point.error)
        assert choice.point == point


@pytest.mark.gl
def test06_render_error_flag(gl_ctx, tmp_path, capsys):
    out = tmp_path / "x.png"
    assert main(["render", "sphere-shading", "-o", str(out), "--size", "48x36",
                 "--shading", "phong", "--error", "0.01"]) == 0
    text = capsys.readouterr().out
    assert "auto quality: objects.0" in text and "<= 0.01" in text and out.is_file()
    assert main(["render", "cornell", "-o", str(out), "--size", "16x16", "--error", "0.01"]) == 0
    assert "no round sphere to tessellate" in capsys.readouterr().out


@pytest.mark.parametrize("value", ["0", "-0.5", "nan", "abc"])
def test07_render_error_flag_bad_input(tmp_path, capsys, value):
    code = main(["render", "sphere-shading", "-o", str(tmp_path / "x.png"), "--error", value])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "--error" in err


def test08_measured_raytrace_front():
    from shadelab.scene.preset import load_preset
    from shadelab.studies.autoquality import front_from_rows
    from shadelab.studies.raytrace_study import COLUMNS, measure

    rows = measure(load_preset("whitted"), (24, 24), (0, 1, 2, 4), (1, 4), (8, 16))
    records = [dict(zip(COLUMNS, r, strict=True)) for r in rows]
    points = front_from_rows(records, ("depth", "spp"), "time_ms")
    best = pareto_front(points)[-1].error
    for budget in (0.1, 2 * best):
        choice = _check_choice(points, budget)
        assert set(choice.point.setting) == {"depth", "spp"}


def test09_raytrace_error_flag(tmp_path, capsys):
    out = tmp_path / "w.png"
    assert main(["raytrace", "whitted", "-o", str(out), "--size", "24x18",
                 "--error", "0.05"]) == 0
    text = capsys.readouterr().out
    assert "auto quality: depth" in text and out.is_file()
    assert main(["raytrace", "whitted", "-o", str(out), "--error", "-1"]) == 2
    assert capsys.readouterr().err.count("\n") == 1


def test10_radiosity_auto_quality():
    from shadelab.scene.preset import load_preset
    from shadelab.studies.radiosity_study import auto_radiosity

    scene = load_preset("radiosity-box")
    patches, resolution, line = auto_radiosity(scene, (32, 32), 0.05, "raycast",
                                               counts=(6, 12, 24))
    assert patches in (6, 12, 24) and resolution == scene.radiosity.hemicube_resolution
    assert "auto quality:" in line and ("<= 0.05" in line or "best reachable" in line)


@pytest.mark.parametrize("value", ["0", "-2", "inf"])
def test11_radiosity_error_flag_bad_input(tmp_path, capsys, value):
    code = main(["radiosity", "cornell", "-o", str(tmp_path / "r.png"), "--error", value])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "--error" in err
