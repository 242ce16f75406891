"""Panels with nothing to show say so instead of showing zeros (issue 22)."""

from __future__ import annotations

import numpy as np

from shadelab.lab.jobs import JobRunner
from shadelab.ui.offline import idle_note
from shadelab.ui.radiosity_view import empty_note


def test_an_all_zero_form_factor_matrix_is_named_not_drawn():
    assert "no patch sees another" in empty_note(np.zeros((6, 6)), 6)
    assert "no patches" in empty_note(None, 0)
    assert "no patches" in empty_note(np.zeros((0, 0)), 0)


def test_a_matrix_still_being_computed_or_with_values_is_drawn():
    assert empty_note(np.zeros((6, 6)), 3) == ""     # rows still coming: the progress bar
    F = np.zeros((3, 3))
    F[0, 1] = 0.2
    assert empty_note(F, 3) == ""


def test_the_offline_panel_says_no_job_before_the_first_one():
    runner = JobRunner()
    assert "no offline job yet" in idle_note(runner)
    runner.started = 1.0
    assert idle_note(runner) == ""
