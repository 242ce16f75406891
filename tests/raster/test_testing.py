"""shadelab.testing: assert_images_close's thresholds, failure images, regeneration, the pytest
plugin, and students' shaders (one that forgets the specular term, one that uses N.L for R.V)."""

from __future__ import annotations

import os
import subprocess
import sys
import textwrap
from pathlib import Path

import numpy as np
import pytest
from PIL import Image as PILImage

from shadelab.errors import ShadeLabError
from shadelab.resources import shaders_dir
from shadelab.testing import THRESHOLDS, assert_images_close, render_with_shaders

LIGHTING = (shaders_dir() / "include" / "lighting.glsl").read_text(encoding="utf-8")
FORGETS_SPECULAR = ("u_kd * od * lambert(n, to_light) + u_ks * u_Os * specular)",
                    "u_kd * od * lambert(n, to_light))")
N_DOT_L_FOR_R_DOT_V = ("lobe_power(dot(reflect_light(n, to_light), to_eye), shininess)",
                       "lobe_power(dot(n, to_light), shininess)")


def _student(mistake: tuple[str, str]) -> str:
    old, new = mistake
    assert LIGHTING.count(old) == 1, "the reference shader changed: update the mistake"
    return LIGHTING.replace(old, new)


def _gray(value: int, shape=(100, 100)) -> np.ndarray:
    return np.full((*shape, 3), value, dtype=np.uint8)


def test_identical_images_pass_every_threshold():
    img = np.random.default_rng(1).integers(0, 256, (40, 30, 3), dtype=np.uint8)
    for name in THRESHOLDS:
        assert assert_images_close(img, img.copy(), name) == {"share": 0.0, "rmse": 0.0,
                                                               "max_diff": 0}


def test_thresholds_closed_cases(tmp_path):
    ref = _gray(100)
    one = ref.copy()
    one[5, 5] = 150  # one pixel of 10 000, 50 levels in 3 channels: RMSE sqrt(3*2500/30000)
    figures = assert_images_close(one, ref, "golden", output_dir=tmp_path)
    assert figures["share"] == pytest.approx(1e-4) and figures["rmse"] == pytest.approx(0.5)
    with pytest.raises(AssertionError, match=r"0\.01% of pixels differ by > 0/255"):
        assert_images_close(one, ref, "exact", name="one", output_dir=tmp_path)
    block = ref.copy()
    block[:20, :20] = 110  # 4 % of pixels, 10 levels
    with pytest.raises(AssertionError, match=r"4\.00% of pixels differ by > 2/255 .*'golden'"):
        assert_images_close(block, ref, "golden", name="block", output_dir=tmp_path)
    diff = np.asarray(PILImage.open(tmp_path / "block_diff.png"))
    assert diff[0, 0, 0] == 160 and diff[50, 50, 0] == 0  # |difference| x 16
    np.testing.assert_array_equal(np.asarray(PILImage.open(tmp_path / "block_img.png")), block)
    np.testing.assert_array_equal(np.asarray(PILImage.open(tmp_path / "block_ref.png")), ref)
    with pytest.raises(AssertionError, match="'driver'"):  # 10 > 8 levels on 4 % > 1 %
        assert_images_close(block, ref, "driver", name="block", output_dir=tmp_path)
    # noisy: 10 <= 16 levels, RMSE sqrt(400 * 3 * 100 / 30000) = 2 <= 8
    assert assert_images_close(block, ref, "noisy")["rmse"] == pytest.approx(2.0)
    with pytest.raises(AssertionError, match="size 50x100 differs from the reference's 100x100"):
        assert_images_close(_gray(100, (100, 50)), ref)
    with pytest.raises(ShadeLabError, match="threshold 'tight'"):
        assert_images_close(ref, ref, "tight")


def test_linear_input_is_srgb_encoded_and_paths_regenerate(tmp_path, monkeypatch):
    linear = np.full((8, 8, 3), 0.5, dtype=np.float32)
    ref = tmp_path / "refs" / "half.png"
    with pytest.raises(AssertionError, match="no reference image .*--shadelab-regenerate"):
        assert_images_close(linear, ref)
    monkeypatch.setenv("SHADELAB_REGENERATE", "1")
    assert assert_images_close(linear, ref) == {"regenerated": str(ref)}
    monkeypatch.delenv("SHADELAB_REGENERATE")
    assert np.asarray(PILImage.open(ref))[0, 0, 0] == 188  # sRGB(0.5)
    assert assert_images_close(linear, ref)["rmse"] == 0.0
    with pytest.raises(AssertionError):
        assert_images_close(linear * 0.9, ref, "exact", output_dir=tmp_path)


@pytest.mark.gl
def test_a_correct_student_shader_passes_and_wrong_ones_fail(gl_ctx, tmp_path):
    import shadelab

    reference = shadelab.render("lecture", size=(96, 72), shading="phong")
    correct = render_with_shaders("lecture", {"lighting": LIGHTING}, size=(96, 72),
                                  shading="phong")
    assert assert_images_close(correct, reference, "golden")["rmse"] == 0.0
    for label, mistake in (("no-specular", FORGETS_SPECULAR), ("n-dot-l", N_DOT_L_FOR_R_DOT_V)):
        student = render_with_shaders("lecture", {"lighting": _student(mistake)},
                                      size=(96, 72), shading="phong")
        with pytest.raises(AssertionError, match=f"{label}: .* of pixels differ"):
            assert_images_close(student, reference, "golden", name=label, output_dir=tmp_path)
        assert (tmp_path / f"{label}_diff.png").is_file()
    # the shared renderer is not left with a student's programs
    again = shadelab.render("lecture", size=(96, 72), shading="phong")
    np.testing.assert_array_equal(again.array, reference.array)


@pytest.mark.gl
def test_a_student_shader_that_does_not_compile(gl_ctx, tmp_path):
    path = tmp_path / "lighting.glsl"
    path.write_text(LIGHTING.replace("return max(dot(n, to_light), 0.0);", "return nope;"))
    with pytest.raises(AssertionError, match="do not compile"):
        render_with_shaders("lecture", {"lighting": path}, size=16)
    with pytest.raises(ShadeLabError, match="include 'lightning': expected one of"):
        render_with_shaders("lecture", {"lightning": LIGHTING}, size=16)


COURSE_TEST = '''
from pathlib import Path
from shadelab.testing import render_with_shaders

def test_student(shadelab_images):
    image = render_with_shaders("lecture", {{"lighting": str(Path(__file__).parent /
                                "student.glsl")}}, size=(64, 48), shading="phong")
    shadelab_images.check("lecture-phong", image)
'''


@pytest.mark.gl
@pytest.mark.slow
def test_plugin_in_a_course_pytest(gl_ctx, tmp_path):
    """A course's own pytest run: the fixture comes from the pytest11 entry point."""
    course = tmp_path / "course"
    course.mkdir()
    (course / "test_course.py").write_text(textwrap.dedent(COURSE_TEST.format()))
    (course / "student.glsl").write_text(LIGHTING)
    env = {k: v for k, v in os.environ.items() if k != "SHADELAB_REGENERATE"}

    def pytest_run(*args):
        return subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                               *args], cwd=course, env=env, capture_output=True, text=True,
                              timeout=300)

    first = pytest_run()
    assert first.returncode == 1 and "no reference image" in first.stdout, first.stdout
    bless = pytest_run("--shadelab-regenerate")
    assert bless.returncode == 0, bless.stdout
    assert (course / "golden" / "lecture-phong.png").is_file()
    assert pytest_run().returncode == 0
    (course / "student.glsl").write_text(_student(FORGETS_SPECULAR))
    wrong = pytest_run()
    assert wrong.returncode == 1 and "lecture-phong:" in wrong.stdout, wrong.stdout
    assert (course / "_output" / "lecture-phong_diff.png").is_file()


def test_golden_module_uses_the_package_thresholds():
    sys.path.insert(0, str(Path(__file__).resolve().parents[2]))
    from tests import golden

    assert (golden.PIXEL_TOLERANCE, golden.MAX_DIFFERING_SHARE, golden.MAX_RMSE) == (2, 0.001,
                                                                                     1.0)
