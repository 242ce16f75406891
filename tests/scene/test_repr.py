"""The API in notebooks (issue 20, item 3): a Scene, its materials, lights and objects have a
readable __repr__ (the lecture's key fields, then what differs from the defaults) and an HTML
repr (small tables) for Jupyter."""

from __future__ import annotations

from html.parser import HTMLParser

import shadelab
from shadelab.scene.model import Light, Material, Object, Scene


class _Cells(HTMLParser):
    def __init__(self):
        super().__init__()
        self.tables = 0
        self.rows: list[list[str]] = []
        self._in_cell = False

    def handle_starttag(self, tag, attrs):
        if tag == "table":
            self.tables += 1
        elif tag == "tr":
            self.rows.append([])
        elif tag in ("td", "th"):
            self._in_cell = True
            self.rows[-1].append("")

    def handle_endtag(self, tag):
        if tag in ("td", "th"):
            self._in_cell = False

    def handle_data(self, data):
        if self._in_cell:
            self.rows[-1][-1] += data


def _cells(html: str) -> _Cells:
    parser = _Cells()
    parser.feed(html)
    return parser


def test_a_material_repr_shows_the_lecture_fields_and_what_changed():
    m = Material(kd=0.5, ks=0.25, n=30.0, Od=(0.9, 0.2, 0.2), kt=0.5)
    assert repr(m) == "Material(ka=0.1, kd=0.5, ks=0.25, n=30, Od=(0.9, 0.2, 0.2), kt=0.5)"
    assert repr(Material()) == "Material(ka=0.1, kd=0.7, ks=0, n=10, Od=(1, 1, 1))"


def test_lights_and_objects_read_like_their_toml():
    light = Light(kind="spot", position=(1.0, 4.0, 2.0), Ip=(2.0, 2.0, 2.0), cone_angle=20.0)
    assert repr(light) == ("Light(kind='spot', position=(1, 4, 2), Ip=(2, 2, 2), "
                           "cone_angle=20)")
    obj = Object(shape="sphere", material="red", radius=0.7, translate=(0.0, 0.7, 0.0))
    assert repr(obj) == ("Object(shape='sphere', material='red', radius=0.7, "
                         "translate=(0, 0.7, 0))")


def test_scene_repr_summarises_and_follows_edits():
    scene = shadelab.load_preset("lecture")
    text = repr(scene)
    first = text.splitlines()[0]
    n = len(scene.objects)
    assert first.startswith("Scene 'lecture': ") and f"{n} objects" in first
    assert f"{len(scene.lights)} light" in first and f"{len(scene.materials)} materials" in first
    name = next(iter(scene.materials))
    scene.materials[name].kd = 0.123
    assert f"materials['{name}']: Material(" in repr(scene) and "kd=0.123" in repr(scene)
    assert len(repr(Scene()).splitlines()) == 3       # header, camera, Ia: nothing else


def test_html_reprs_are_small_tables():
    scene = shadelab.load_preset("cornell")
    html = scene._repr_html_()
    cells = _cells(html)
    assert cells.tables == 3                               # lights, materials, objects
    headers = [row[0] for row in cells.rows if row and row[0] in ("lights", "materials",
                                                                    "objects")]
    assert headers == ["lights", "materials", "objects"]
    assert len(cells.rows) == 3 + len(scene.lights) + len(scene.materials) + len(scene.objects)
    red = next(row for row in cells.rows if row[0] == "red")
    assert red[1:5] == ["0", "1", "0", "10"]               # ka kd ks n as the preset has them
    material = _cells(scene.materials["red"]._repr_html_())
    assert material.tables == 1 and ["kd", "1"] in material.rows
    evil = Scene(description="<script>x</script>")
    assert "<script>" not in evil._repr_html_()          # text is escaped
