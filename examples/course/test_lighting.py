"""A course's autograder for the lighting exercise: the student's ``lighting.glsl`` renders
the lecture's scene (shadow volumes on) and is compared with the references in ``golden/``.

Run from this folder::

    SHADELAB_SUBMISSION=submissions/correct pytest

``shadelab_images.render`` draws the lecture's exact equation (ini ``shadelab_exact``, default
true): ShadeLab's terminator fade under shadow volumes, which no student writes, stays out of
the image and of the references. The references were written from the correct submission with
``pytest --shadelab-regenerate``.
"""

from __future__ import annotations

import os
from pathlib import Path

import pytest

HERE = Path(__file__).resolve().parent
SUBMISSION = HERE / os.environ.get("SHADELAB_SUBMISSION", "submissions/correct")


@pytest.mark.parametrize("shading", ["phong", "gouraud"])
def test_lecture(shadelab_images, shading):
    image = shadelab_images.render("lecture", {"lighting": SUBMISSION / "lighting.glsl"},
                                   size=(160, 120), shading=shading)
    shadelab_images.check(f"lecture-{shading}", image)
