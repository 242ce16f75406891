"""A new offline pipeline is one file plus one test (ARCHITECTURE.md, "Pipelines"): this toy
"albedo" pipeline is registered here and nowhere else, yet shadelab.render, the CLI's generic
``render --pipeline`` path, the Offline panel's job list and the job runner all accept it."""

from __future__ import annotations

import time

import numpy as np
import pytest

import shadelab
from shadelab import api, pipelines
from shadelab.cli import main
from shadelab.errors import ShadeLabError
from shadelab.progress import Progress

COLOUR = (0.25, 0.5, 0.75)


class Albedo(pipelines.BasePipeline):
    """Every pixel one constant colour, row by row (a progressive job in miniature)."""

    name = "albedo"
    label = "constant albedo (toy)"
    default_size = (12, 8)
    job_label = "Albedo (toy)"
    job_order = 9

    def check(self, scene, label=""):
        if not scene.objects:
            raise ShadeLabError(f"{label}: objects: the scene is empty")

    def run(self, scene, size):
        w, h = size
        image = np.zeros((h, w, 3), np.float32)
        for y in range(h):
            image[y] = COLOUR
            yield Progress(image.copy(), (y + 1) / h, f"row {y + 1}/{h}")


@pytest.fixture
def albedo():
    with pipelines.registered(Albedo()) as pipeline:
        yield pipeline


def expected(w, h):
    return np.broadcast_to(np.asarray(COLOUR, np.float32), (h, w, 3))


def test_render_accepts_a_registered_pipeline(albedo):
    image = shadelab.render("cornell", size=(10, 6), pipeline="albedo")
    np.testing.assert_array_equal(image.array, expected(10, 6))  # exact: a constant
    assert image.info["pipeline"] == "albedo" and image.size == (10, 6)
    assert shadelab.render("cornell", pipeline="albedo").size == (12, 8)  # its default size
    assert "albedo" in api.PIPELINES
    with pytest.raises(ShadeLabError, match="applies to the raster and painter"):
        shadelab.render("cornell", pipeline="albedo", shading="flat")


def test_the_cli_generic_path_accepts_it(albedo, tmp_path, capsys):
    npy = tmp_path / "albedo.npy"
    assert main(["render", "cornell", "--pipeline", "albedo", "--size", "9x5",
                 "-o", str(tmp_path / "albedo.png"), "--npy", str(npy)]) == 0
    np.testing.assert_array_equal(np.load(npy), expected(9, 5))
    assert "(9x5, albedo)" in capsys.readouterr().out
    assert main(["render", "cornell", "--pipeline", "albedo", "--shading", "flat",
                 "-o", str(tmp_path / "x.png")]) == 2
    assert "--shading: applies to the raster pipelines, not albedo" in capsys.readouterr().err


def test_the_job_runner_and_the_offline_panel_list_accept_it(albedo):
    from shadelab.lab.jobs import JobRunner, available_jobs, find_job

    kind = find_job("albedo")
    assert kind is not None and kind.label == "Albedo (toy)"
    assert [k.pipeline for k in available_jobs()][-1] == "albedo"
    scene = shadelab.load_preset("cornell")
    for viewport, final_fraction in ((False, 1.0), (True, 1.0)):
        runner = JobRunner()  # a test's pipeline is unknown to the worker: runs in a thread
        runner.start_pipeline("albedo", scene, (16, 8), viewport=viewport)
        deadline = time.time() + 20
        while runner.running and time.time() < deadline:
            time.sleep(0.01)
        assert not runner.running and runner.error == "" and not runner.in_process
        last, _ = runner.snapshot()
        np.testing.assert_array_equal(last.image, expected(16, 8))
        assert last.fraction == final_fraction
        if viewport:  # coarse to fine: 1/8, 1/4, 1/2, full, the last one held back as done
            sizes = [t["level"] for t in runner.trail]
            assert sizes[0] == 8 and sizes[-1] == 1 and runner.trail[-1]["done"]
        runner.shutdown()


def test_unregistered_after_the_block():
    assert "albedo" not in pipelines.names()
    with pytest.raises(ShadeLabError, match="pipeline 'albedo': expected one of raster"):
        shadelab.render("cornell", pipeline="albedo")
