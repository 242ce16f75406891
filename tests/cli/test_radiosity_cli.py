"""``shadelab radiosity``: a small run per option, and every bad input as one line, exit 2."""

from __future__ import annotations

import numpy as np
import pytest

from shadelab.cli import main


def _one_line_error(capsys, argv, needle):
    assert main(argv) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1, err
    assert err[0].startswith("shadelab: error:") and needle in err[0]


@pytest.mark.gl
@pytest.mark.parametrize("extra", [["--solver", "jacobi", "--uniform"],
                                   ["--solver", "progressive"],
                                   ["--form-factors", "hemicube", "--solver", "gauss-seidel",
                                    "--set", "radiosity.hemicube_resolution=32"]])
def test01_radiosity_writes_png_and_npy(tmp_path, capsys, gl_ctx, extra):
    """Cornell at 40 patches: the light's pixels hold its radiance, the walls a fraction."""
    png, npy = tmp_path / "r.png", tmp_path / "r.npy"
    assert main(["radiosity", "cornell", "-o", str(png), "--npy", str(npy), "--size", "32x32",
                 "--patches", "40", *extra]) == 0
    assert png.is_file()
    image = np.load(npy)
    assert image.shape == (32, 32, 3) and image.dtype == np.float32
    assert np.all(np.isfinite(image)) and image.min() >= 0.0
    np.testing.assert_allclose(image.max(axis=(0, 1)), [20.71, 10.85, 2.77], rtol=1e-4)
    walls = image[image.max(axis=2) < 2.0]
    assert 0.05 < walls[:, 0].mean() < 0.5  # red channel of the lit room, radiance units
    assert "patches" in capsys.readouterr().out


@pytest.mark.parametrize("patches", ["0", "-5"])
def test02_bad_patch_count(tmp_path, capsys, patches):
    _one_line_error(capsys, ["radiosity", "cornell", "-o", str(tmp_path / "x.png"),
                             "--patches", patches], "--patches")


def test03_no_emitter(tmp_path, capsys):
    _one_line_error(capsys, ["radiosity", "cornell", "-o", str(tmp_path / "x.png"),
                             "--set", "materials.light.emission=0,0,0"], "emission")


def test04_reflectance_one_in_a_closed_room(tmp_path, capsys):
    """rho = 1 on every surface of a closed room (the light reflects too): refused at once."""
    _one_line_error(capsys, ["radiosity", "radiosity-box", "-o", str(tmp_path / "x.png"),
                             "--patches", "40", "--uniform",
                             "--set", "materials.white.Od=1,1,1",
                             "--set", "materials.light.kd=1", "--set", "materials.light.Od=1,1,1"],
                    "no bounded solution")


def test05_reflectance_above_one(tmp_path, capsys):
    _one_line_error(capsys, ["radiosity", "radiosity-box", "-o", str(tmp_path / "x.png"),
                             "--patches", "40", "--set", "materials.white.Od=1.3,1.3,1.3"],
                    "materials.white")


@pytest.mark.parametrize("flag, value", [("--solver", "newton"), ("--form-factors", "guess"),
                                         ("--patches", "many"), ("--size", "0x5")])
def test06_bad_flags(tmp_path, capsys, flag, value):
    _one_line_error(capsys, ["radiosity", "cornell", "-o", str(tmp_path / "x.png"), flag, value],
                    value if flag != "--size" else "--size")


def test07_unwritable_output(tmp_path, capsys):
    _one_line_error(capsys, ["radiosity", "cornell", "-o", str(tmp_path / "no" / "x.png")],
                    "does not exist")
