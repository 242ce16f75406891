"""One caption band per lesson (issue 22): the band under the viewport is measured once for
all of a lesson's steps (the tallest caption at the width and font), so the scene keeps its
size and place from step to step."""

from __future__ import annotations

import math

import pytest

from shadelab.lab.lesson import LessonRun, load_lesson
from shadelab.ui.presenter import lesson_band_height, lesson_captions


def wrapped_height(width: float, char_px: float, line_px: float):
    """A stand-in for ImGui's measure: each line wrapped to ``width``, plus padding."""
    def measure(text: str) -> float:
        per_line = max(int(width // char_px), 1)
        lines = sum(max(math.ceil(len(line) / per_line), 1) for line in text.split("\n"))
        return lines * line_px + 2.5 * 10.0
    return measure


@pytest.mark.parametrize("width,char_px,line_px", [(1024, 14.0, 25.0), (1920, 14.0, 25.0),
                                                   (1024, 25.0, 45.0)])
def test_the_band_is_the_same_for_every_step_of_a_lesson(width, char_px, line_px):
    lesson = load_lesson("phong-to-radiosity")
    captions = lesson_captions(lesson)
    assert len(captions) == len(lesson.steps) and all(captions)
    assert captions[0] == LessonRun(lesson, 0).caption()
    measure = wrapped_height(width, char_px, line_px)
    heights = {measure(c) for c in captions}
    if width == 1024:                    # the captions do differ: a per-step band would jump
        assert len(heights) > 1
    bands = [lesson_band_height(captions, measure) for _ in lesson.steps]
    assert len(set(bands)) == 1 and bands[0] == max(heights)


def test_a_lesson_without_captions_keeps_no_band():
    assert lesson_band_height([], len) == 0.0
    assert lesson_band_height(["", ""], len) == 0.0
