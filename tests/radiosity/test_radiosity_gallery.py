"""The radiosity failure gallery: each artefact reproduced, measured, and its fix shown."""

from __future__ import annotations

import numpy as np
import pytest

from shadelab.radiosity import gallery


@pytest.mark.gl
def test01_hemicube_aliasing(gl_ctx):
    """A 0.2-wide square one unit above the receiver's centre, slid across by its own width.
    At 8 x 8 a pixel (0.25 wide) is larger than the square: it is missed (F = 0) or caught
    by one pixel (+50 %..+73 %) depending on where it falls. At 256 x 256 it spans ~25 pixels
    and the error stays within 5 %."""
    from shadelab.raster.hemicube import Hemicube

    result = gallery.hemicube_aliasing((8, 256), hemicube=Hemicube)
    low, high = result["relative_error"][8], result["relative_error"][256]
    assert low.min() == pytest.approx(-1.0)  # missed entirely
    assert low.max() > 0.4  # one pixel's delta form factor, too big
    assert np.abs(high).max() < 0.05


def test02_light_leak_under_a_block():
    """The floor under the block gets no light (exact: 0). At 40 patches the floor is 2 x 2
    and each patch runs a quarter of the block's base under it: the hidden part shares its
    mostly lit patch's radiosity, more than half the lit floor's mean (measured: 93 %).
    Cutting the floor along the block's base: exactly 0. (At 60 patches the floor is 3 x 3,
    its centre patch lies all under the block and the leak vanishes: the artefact depends on
    how the mesh meets the contact line, which is why the fix is to mesh along it.)"""
    result = gallery.light_leak(40)
    assert result["unsplit"] > 0.5 * result["lit_floor_mean"]
    assert result["split"] == pytest.approx(0.0, abs=1e-12)


def test03_t_vertex_cracks():
    """Adaptive subdivision of the leak room: T-vertices where fine meets coarse. Naively
    drawn, the coarse side interpolates its own corners along the shared edge and the
    values jump (by more than 5 % of the room's mean radiance somewhere); the conforming
    fan triangulation shares every vertex: no open edge inside a surface."""
    report = gallery.t_vertex_cracks(120)
    mean = float(report["solution"].radiance.mean())
    assert report["t_vertices"] > 0
    assert report["naive_open_edges"] > 0 and report["conforming_open_edges"] == 0
    assert report["max_jump"] > 0.05 * mean
