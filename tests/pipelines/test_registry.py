"""The registry is the one list of pipelines: every reader agrees with it."""

from __future__ import annotations

import pickle

import numpy as np
import pytest

import shadelab
from shadelab import api, pipelines
from shadelab.cli import main
from shadelab.errors import ShadeLabError


def test_names_and_the_readers_agree():
    assert pipelines.names()[:4] == ("painter", "gouraud", "phong", "flat")
    assert {"radiosity", "raytrace", "pathtrace", "reference"} <= set(pipelines.names())
    assert api.PIPELINES == ("raster",) + pipelines.names()
    from shadelab.lab import pipeline_view

    # the viewer's selector keeps its order and labels
    assert pipeline_view.PIPELINES == ("gouraud", "phong", "painter", "radiosity", "raytrace",
                                       "pathtrace")
    assert pipeline_view.RASTER == {"gouraud": ("gouraud", "zbuffer"),
                                    "phong": ("phong", "zbuffer"),
                                    "painter": ("phong", "painter")}
    from shadelab.lab.jobs import available_jobs

    assert [k.pipeline for k in available_jobs()] == ["reference", "raytrace", "pathtrace",
                                                      "radiosity"]
    for name in pipelines.all_names():
        p = pipelines.get(name)
        assert isinstance(p, pipelines.Pipeline) and p.output in (pipelines.IMAGE,
                                                                   pipelines.TRIANGLES)
        assert pickle.loads(pickle.dumps(p)) is p  # by name: the worker process finds it


def test_bad_names_are_one_line_errors(capsys):
    with pytest.raises(ShadeLabError, match=r"^pipeline 'toon': expected one of raster, "
                                            r"painter, gouraud"):
        pipelines.get("toon")
    assert main(["view", "cornell", "--pipeline", "toon"]) == 2  # was an ImportError
    err = capsys.readouterr().err
    assert "--pipeline 'toon': expected one of gouraud, phong, painter" in err
    assert len(err.strip().splitlines()) == 1
    with pytest.raises(ShadeLabError, match="the gouraud pipeline shades gouraud"):
        shadelab.render("cornell", pipeline="gouraud", shading="phong")


@pytest.mark.gl
@pytest.mark.parametrize("shading", ["gouraud", "phong", "flat"])
def test_render_by_shading_name_equals_raster_with_that_shading(gl_ctx, shading):
    by_name = shadelab.render("cornell", size=(40, 30), pipeline=shading)
    by_flag = shadelab.render("cornell", size=(40, 30), shading=shading)
    np.testing.assert_array_equal(by_name.array, by_flag.array)  # same renderer, exact
    assert by_name.info["shading"] == shading and by_name.array.max() > 0.0


def test_builtins_pickle_by_name_when_imported_before_the_registry(tmp_path):
    """lab.pipeline_jobs imports pipelines.radiosity directly: it is still a built-in."""
    import subprocess
    import sys

    code = ("import pickle, shadelab.lab.pipeline_jobs\n"
            "from shadelab import pipelines\n"
            "p = pipelines.get('radiosity')\n"
            "assert pickle.loads(pickle.dumps(p)) is p\nprint('ok')")
    out = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True)
    assert out.stdout.strip() == "ok", out.stderr[-2000:]
