"""``shadelab bench`` runs and writes its JSON (figures are reported, never asserted as speed)."""

from __future__ import annotations

import json
import math

import pytest

from shadelab.cli import main


@pytest.mark.gl
@pytest.mark.slow
def test_bench_quick_raster_and_shadows_write_json(tmp_path, capsys):
    out = tmp_path / "bench.json"
    assert main(["bench", "--quick", "--only", "raster", "--only", "shadows",
                 "--json", str(out)]) == 0
    report = json.loads(out.read_text())
    assert report["machine"]["cores"] >= 1 and "gl_renderer" in report["machine"]
    raster, shadows = report["sections"]["raster"], report["sections"]["shadows"]
    for key in ("cornell_phong_over_bare", "sphere_shading_phong_over_bare",
                "mesh80k_phong_over_bare"):
        assert math.isfinite(raster[key]) and raster[key] > 0, key
    pairs = raster["phong_vs_bare_interleaved"]
    assert set(pairs) == {"cornell", "sphere_shading", "mesh80k"}
    assert pairs["mesh80k"]["triangles"] == 20 * 4 ** 6
    assert "ctx.finish()" in raster["phong_vs_bare_fairness"]
    assert raster["frame_ms"]["cornell/phong"]["median_ms"] > 0
    assert math.isfinite(shadows["ratio_shadowed_over_unshadowed"])
    assert set(report["sections"]) == {"raster", "shadows"}


def test_bench_rejects_unknown_section(capsys):
    assert main(["bench", "--only", "gpu-magic"]) == 2
    assert "--only 'gpu-magic'" in capsys.readouterr().err
