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
from shadelab.testing import (
    THRESHOLDS,
    assert_images_close,
    reference_image,
    render_with_shaders,
)

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

    first = shadelab.render("lecture", size=(96, 72), shading="phong")
    # a course's reference: the exact equation (no terminator fade), as render_with_shaders
    # draws by default (tests/raster/test_course.py)
    reference = reference_image("lecture", size=(96, 72), shading="phong")
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
    np.testing.assert_array_equal(again.array, first.array)


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


# ---------------------------------------------------------------- an autograder's messages

FORGETS_F_ATT = ("vec3 scale = s * f_att * spot * LIGHT_IP(i);",
                 "vec3 scale = s * spot * LIGHT_IP(i);")
BLINN_FOR_PHONG = ("else specular = phong_specular(n, to_light, to_eye, u_n);",
                   "else specular = blinn_phong_specular(n, to_light, to_eye, u_n);")


@pytest.mark.gl
@pytest.mark.parametrize("mistake, term", [
    (FORGETS_SPECULAR, "the specular term ks·Os·(R·V)^n"),
    (FORGETS_F_ATT, "the attenuation f_att"),
    (BLINN_FOR_PHONG, "the specular model"),
])
def test_a_failure_names_the_likeliest_wrong_term(gl_ctx, tmp_path, mistake, term):
    import shadelab

    reference = shadelab.render("lecture", size=(64, 48), shading="phong")
    student = render_with_shaders("lecture", {"lighting": _student(mistake)}, size=(64, 48),
                                  shading="phong")
    with pytest.raises(AssertionError) as failure:
        assert_images_close(student, reference, "golden", name="s", output_dir=tmp_path)
    message = str(failure.value)
    assert f"likeliest wrong term: {term}" in message, message
    # the named variant explains the image (RMSE well under the full equation's)
    best, full = (float(v) for v in
                  __import__("re").findall(r"RMSE (\d+\.\d+)/255 of the reference rendered that "
                                           r"way, (\d+\.\d+)/255", message)[0])
    assert best < 0.5 * full


@pytest.mark.gl
def test_a_compile_error_names_the_students_file_and_line(gl_ctx, tmp_path):
    path = tmp_path / "my_lighting.glsl"
    text = LIGHTING.replace("return max(dot(n, to_light), 0.0);", "return nope;")
    path.write_text(text)
    line = text.splitlines().index(next(x for x in text.splitlines() if "nope" in x)) + 1
    with pytest.raises(AssertionError, match=rf"{path}:{line}:\d+: error: `nope' undeclared"):
        render_with_shaders("lecture", {"lighting": path}, size=16)
    with pytest.raises(AssertionError, match=rf"<include lighting>:{line}:\d+: error"):
        render_with_shaders("lecture", {"lighting": text}, size=16)


# ---------------------------------------------------------------- misuse: one clear line


@pytest.mark.parametrize("threshold, match", [
    (["golden"], "threshold \\['golden'\\]: expected one of"),
    (3, "threshold 3: expected one of"),
])
def test_a_threshold_of_the_wrong_type_is_one_line(threshold, match):
    with pytest.raises(ShadeLabError, match=match):
        assert_images_close(_gray(1), _gray(1), threshold)


@pytest.mark.parametrize("fields, match", [
    ((-1, 0.0, 0.0), "pixel -1"), ((2, -0.1, 1.0), "max_share -0.1"),
    ((2, 0.1, float("nan")), "max_rmse nan"), ((2.5, 0.1, 1.0), "pixel 2.5"),
])
def test_a_custom_threshold_out_of_range_is_refused(fields, match):
    from shadelab.testing import Threshold

    with pytest.raises(ShadeLabError, match=match):
        Threshold(*fields)
    assert Threshold(0, 0.0, 0.0) == THRESHOLDS["exact"]


def test_nan_images_never_pass_and_odd_dtypes_and_exposures_are_refused():
    nan = np.full((4, 4, 3), np.nan, dtype=np.float32)
    with pytest.raises(AssertionError, match="48 NaN or infinite values"):
        assert_images_close(nan, nan.copy())
    with pytest.raises(ShadeLabError, match="expected uint8 \\(sRGB\\) or float .* got int64"):
        assert_images_close(np.zeros((4, 4, 3), np.int64), _gray(0, (4, 4)))
    with pytest.raises(ShadeLabError, match="exposure '2': expected a finite number > 0"):
        assert_images_close(_gray(0, (4, 4)), _gray(0, (4, 4)), exposure="2")


def test_broken_reference_files_are_one_line(tmp_path):
    fake = tmp_path / "fake.png"
    fake.write_text("not a png")
    noise = np.random.default_rng(2).integers(0, 256, (64, 64, 3), dtype=np.uint8)
    good = tmp_path / "good.png"
    PILImage.fromarray(noise).save(good)
    cut = tmp_path / "cut.png"
    cut.write_bytes(good.read_bytes()[:len(good.read_bytes()) // 2])
    for path in (fake, cut):
        with pytest.raises(ShadeLabError, match=f"{path.name}: not a readable image"):
            assert_images_close(noise, path)
    assert assert_images_close(noise, good)["rmse"] == 0.0


def test_regenerating_onto_a_folder_or_under_a_file_is_one_line(tmp_path):
    folder = tmp_path / "golden.png"
    folder.mkdir()
    with pytest.raises(ShadeLabError, match="is a folder, not an image file"):
        assert_images_close(_gray(7, (8, 8)), folder, regenerate=True)
    blocker = tmp_path / "not-a-folder"
    blocker.write_text("a file where the golden folder should be")
    with pytest.raises(ShadeLabError, match="not-a-folder/x.png: cannot write"):
        assert_images_close(_gray(7, (8, 8)), blocker / "x.png", regenerate=True)
    assert not list(tmp_path.rglob("*.tmp"))


def test_regenerating_into_a_full_disk_is_one_line_and_leaves_nothing(tmp_path, monkeypatch):
    import errno

    from PIL import Image as PILModule

    def full(self, fp, *args, **kwargs):
        raise OSError(errno.ENOSPC, "No space left on device")

    monkeypatch.setattr(PILModule.Image, "save", full)
    with pytest.raises(ShadeLabError, match="x.png: cannot write \\(No space left on device\\)"):
        assert_images_close(_gray(7, (8, 8)), tmp_path / "x.png", regenerate=True)
    assert list(tmp_path.iterdir()) == []


def test_a_shader_mapping_of_the_wrong_kind_is_one_line(tmp_path):
    with pytest.raises(ShadeLabError, match="includes: expected a mapping"):
        render_with_shaders("lecture", ["lighting.glsl"], size=16)
    with pytest.raises(ShadeLabError, match="include 'lighting': expected GLSL text or a .glsl"):
        render_with_shaders("lecture", {"lighting": 5}, size=16)
    latin = tmp_path / "latin.glsl"
    latin.write_bytes(b"// caf\xe9\n")
    with pytest.raises(ShadeLabError, match="latin.glsl: shader is not UTF-8 text"):
        render_with_shaders("lecture", {"lighting": latin}, size=16)
