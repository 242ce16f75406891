"""The lecture's exact equation for autograders (issue 20, item 7).

Under shadow volumes ShadeLab's lit pass fades S_i near the terminator; a student who writes
the lecture's equation has no such term. ``render_with_shaders(..., exact=True)`` (the
default) and ``shadelab_images.render`` draw with a Renderer whose terminator fade is off
(u_terminator = 0), so a faithful student chunk matches the exact reference. The example
course in ``examples/course`` runs as a real pytest session per submission.
"""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from shadelab.testing import assert_images_close, reference_image, render_with_shaders

pytestmark = pytest.mark.gl
COURSE = Path(__file__).resolve().parents[2] / "examples" / "course"
CORRECT = COURSE / "submissions" / "correct" / "lighting.glsl"
SIZE = (160, 120)


@pytest.mark.parametrize("shading", ["phong", "gouraud"])
def test_faithful_student_chunk_matches_the_exact_reference(gl_ctx, shading):
    """The lecture (shadow volumes on, smooth spheres): the correct submission against
    ShadeLab's own shaders with the fade off, within the 'golden' threshold (in fact to
    RMSE < 0.05/255); with the fade on (exact=False) the stock frame differs on the spheres'
    terminator bands, which a student's chunk has no way to draw."""
    student = render_with_shaders("lecture", {"lighting": CORRECT}, SIZE, shading)
    exact = reference_image("lecture", SIZE, shading)
    figures = assert_images_close(student, exact, "golden", regenerate=False)
    assert figures["rmse"] < 0.05
    faded = reference_image("lecture", SIZE, shading, exact=False)
    assert np.abs(np.asarray(faded) - np.asarray(exact)).max() > 0.02


def test_exact_is_the_default_and_turns_only_the_fade_off(gl_ctx):
    """exact=True is render_with_shaders' default; the stock chunk with exact=False is the
    frame shadelab.render draws (fade on)."""
    from shadelab.api import render

    stock = Path(__file__).resolve().parents[2] / "shaders" / "include" / "lighting.glsl"
    default = render_with_shaders("lecture", {"lighting": stock}, SIZE, "phong")
    exact = reference_image("lecture", SIZE, "phong", exact=True)
    np.testing.assert_allclose(np.asarray(default), np.asarray(exact), atol=1e-5)
    faded = render_with_shaders("lecture", {"lighting": stock}, SIZE, "phong", exact=False)
    np.testing.assert_allclose(np.asarray(faded),
                               np.asarray(render("lecture", size=SIZE, shading="phong")),
                               atol=1e-5)


def _run_course(submission: str, tmp_path: Path) -> subprocess.CompletedProcess:
    env = dict(os.environ)  # the inherited PYTHONPATH stays
    env["SHADELAB_SUBMISSION"] = f"submissions/{submission}"
    return subprocess.run(
        [sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
         "-o", f"shadelab_output_dir={tmp_path}", str(COURSE / "test_lighting.py")],
        cwd=COURSE, env=env, capture_output=True, text=True, timeout=600)


@pytest.mark.slow
@pytest.mark.parametrize(("submission", "term"), [
    ("correct", None),
    ("no-specular", "the specular term ks·Os·(R·V)^n (left out)"),
    ("no-attenuation", "the attenuation f_att (taken as 1)"),
])
def test_example_course_grades_each_submission(tmp_path, submission, term):
    """A real pytest session on examples/course: the correct submission passes both tests;
    each wrong one fails both, naming its wrong term."""
    done = _run_course(submission, tmp_path)
    out = done.stdout + done.stderr
    if term is None:
        assert done.returncode == 0, out
        assert "2 passed" in out
    else:
        assert done.returncode == 1, out
        assert "2 failed" in out
        assert out.count(f"likeliest wrong term: {term}") >= 2, out
