"""Helpers for the exercise tests: write a small exercise file (64x48 images) and grade it."""

from __future__ import annotations

from pathlib import Path

import pytest


@pytest.fixture
def write_exercise(tmp_path):
    def write(body: str, name: str = "ex.toml") -> Path:
        path = tmp_path / name
        path.write_text('name = "test"\n' + body, encoding="utf-8")
        return path
    return write
