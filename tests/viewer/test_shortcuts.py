"""The viewer's key table on every interpreter CI runs (Debian 12's python3 is 3.11.2).

Python < 3.11.4's enum raised AttributeError when two imgui.Key members (an IntFlag) were
OR-ed into a chord with a bit no member names, so importing ``shadelab.ui.app`` crashed the
viewer at start. The table holds plain ints, which every interpreter ORs the same way.
"""

import sys

import pytest

imgui = pytest.importorskip("imgui_bundle").imgui


def test_the_key_table_imports_on_this_interpreter():
    from shadelab.ui import app

    assert len(app.SHORTCUTS) >= 20, sys.version


def test_modifier_chords_are_plain_ints_with_ctrl_and_the_key():
    from shadelab.ui.app import SHORTCUTS

    ctrl = int(imgui.Key.mod_ctrl)
    chords = {shown: chord for chord, shown, _, _ in SHORTCUTS if shown.startswith("Ctrl+")}
    assert set(chords) == {"Ctrl+Z", "Ctrl+Y", "Ctrl+S"}
    for shown, chord in chords.items():
        assert type(chord) is int, shown  # no enum arithmetic left for an old enum module
        key = getattr(imgui.Key, shown[-1].lower())
        assert chord == ctrl | int(key), shown
        assert chord & ~ctrl == int(key), shown


def test_no_enum_arithmetic_on_imgui_keys_in_the_package_or_its_tests():
    """``Key.a | Key.b`` is the crash; every chord ORs ints (``int(Key.a) | int(Key.b)``)."""
    import re
    from pathlib import Path

    root = Path(__file__).resolve().parents[2]
    pattern = re.compile(r"\bKey\.\w+\s*\||\|\s*(?:imgui\.)?Key\.\w+|\bK\.\w+\s*\||\|\s*K\.\w+")
    offenders = [f"{path.relative_to(root)}:{n}"
                 for path in [*(root / "app").rglob("*.py"), *(root / "tests").rglob("*.py")]
                 for n, line in enumerate(path.read_text(encoding="utf-8").splitlines(), 1)
                 if pattern.search(line) and path.name != "test_shortcuts.py"]
    assert not offenders
