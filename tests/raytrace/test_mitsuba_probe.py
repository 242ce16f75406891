"""The bench's Mitsuba comparison first renders in a child process (bench.raytrace
mitsuba_usable): Dr.Jit's LLVM backend on an old libLLVM aborts its process, which must end
the comparison with a named reason, never the whole bench."""

from __future__ import annotations

import importlib.util
import os
import sys

import pytest

from shadelab.bench import raytrace


def _fake_python(tmp_path, body: str) -> str:
    path = tmp_path / "python"
    path.write_text(f"#!{sys.executable}\nimport os, sys\n{body}\n", encoding="utf-8")
    os.chmod(path, 0o755)
    return str(path)


def test_an_aborting_render_is_a_named_skip(tmp_path, monkeypatch):
    monkeypatch.setattr(raytrace, "_mitsuba_usable", {})
    python = _fake_python(tmp_path, "sys.stderr.write('LLVM ERROR: Cannot select\\n')\n"
                                    "os.abort()")
    why = raytrace.mitsuba_usable(python)
    assert why is not None and "exit -6" in why and "Cannot select" in why
    assert "apt-get install libllvm19" in why and "\n" not in why
    assert raytrace.mitsuba_usable(python) is why          # asked once per interpreter


def test_a_hanging_render_is_a_named_skip(tmp_path, monkeypatch):
    monkeypatch.setattr(raytrace, "_mitsuba_usable", {})
    monkeypatch.setattr(raytrace, "MITSUBA_PROBE_TIMEOUT_S", 1)
    why = raytrace.mitsuba_usable(_fake_python(tmp_path, "import time; time.sleep(30)"))
    assert why is not None and "over 1 s" in why


@pytest.mark.skipif(importlib.util.find_spec("mitsuba") is None,
                    reason="Mitsuba 3 is the optional bench extra's")
def test_an_installed_mitsuba_renders(monkeypatch):
    monkeypatch.setattr(raytrace, "_mitsuba_usable", {})
    assert raytrace.mitsuba_usable() is None
