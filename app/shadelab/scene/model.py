"""The scene as plain data: camera, lights, materials, objects and render settings.

Every field carries a validation spec in its metadata (``spec``), so the preset loader, the
``--set`` overrides, the viewer's sliders and ``presets/schema.json`` all read one table.
The classes are mutable on purpose: the viewer edits them live, one slider at a time.
Names follow the lecture (``Ia``, ``ka``, ``kd``, ``ks``, ``n``, ``Od``, ``Os``, ``Ip``,
``kt``, ``Ot``) so that a ``--set`` path reads like the slide.
"""

from __future__ import annotations

import itertools
from dataclasses import MISSING, dataclass, field, fields
from typing import Any

Rgb = tuple[float, float, float]
Point3 = tuple[float, float, float]
Vec3 = tuple[float, float, float]

SCHEMA_VERSION = 1
MAX_LIGHTS = 16  # the GLSL light arrays hold this many

SHADING_MODES = ("flat", "gouraud", "phong")
SPECULAR_MODELS = ("phong", "blinn")
LIGHT_KINDS = ("point", "directional", "spot")  # shadelab.shading.lights: one class each
AIMED_LIGHT_KINDS = ("directional", "spot")  # kinds whose direction must be non-zero
ATTENUATION_MODES = ("none", "inverse_square", "lecture")
NORMALS_MODES = ("flat", "average", "area", "angle", "crease")
SHAPES = ("sphere", "box", "plane", "quad", "cylinder", "cone", "torus", "capsule", "mesh")
TRANSPARENCY_MODELS = ("interpolated", "filtered")
RADIOSITY_SOLVERS = ("direct", "jacobi", "gauss-seidel", "progressive")
RADIOSITY_MESHINGS = ("uniform", "adaptive", "discontinuity")


def spec(default: Any, kind: str, *args: Any, doc: str = "") -> Any:
    """Declare a dataclass field with a validation spec.

    kind is one of ``float`` (min, max), ``int`` (min, max), ``bool``, ``str`` (choices or
    None), ``rgb`` (three floats in [0, max]), ``rgb01`` (a reflectance color in [0, 1]),
    ``vec3`` (three floats in [min, max]), ``vec3s`` (a list of vec3, (min, max)).
    Every number has a finite range (see the ``*_MAX`` constants), so no value a preset may
    hold overflows a float64 computation or a float32 GPU buffer.
    """
    meta = {"spec": (kind, *args), "doc": doc}
    if isinstance(default, (list, dict)):
        return field(default_factory=lambda: type(default)(default), metadata=meta)
    return field(default=default, metadata=meta)


# The finite ranges every number of a preset lives in (decided once, here). A coordinate of
# 1e9 world units is 1000 km in a millimetre scene; squared (1e18) and summed it stays far
# from float32's 3.4e38, so shaders, Embree and numpy never overflow.
LENGTH_MAX = 1e9  # coordinates, sizes, distances, world units
SCALE_MAX = 1e6  # per-axis object scale (scale x size stays within 1e15)
INTENSITY_MAX = 1e12  # Ip, Ia, emission, background: linear RGB
COEFF_MAX = 1e12  # attenuation coefficients c1, c2, c3
COORD = (-LENGTH_MAX, LENGTH_MAX)


class Checked:
    """Assignments to a spec'd field after construction are validated as a preset value is.

    ``scene.materials["white"].kd = 1.5`` raises :class:`~shadelab.errors.ShadeLabError`
    (``Material: key 'kd': expected a number in [0, 1], got 1.5``) and the value stays as it
    was; a valid value is stored in canonical form (a list of three numbers becomes a tuple).
    Construction itself is not checked (the preset loader checks every key it sets).

    Every object carries an edit stamp (``_stamp``; a copy keeps its original's): made anew at
    construction and by every assignment that changes a value (a slider that writes back the
    same value leaves it). :attr:`Scene.version` reads the stamps of the whole scene.
    """

    def __setattr__(self, name: str, value: Any) -> None:
        if self.__dict__.get("_checked"):
            specs = _SPECCED.get(type(self))
            if specs is None:
                specs = _SPECCED[type(self)] = {f.name for f in fields(self)
                                               if "spec" in f.metadata}
            if name in specs:
                value = _VALIDATE(type(self), name, value, type(self).__name__, name)
            if _changes(self.__dict__.get(name, _MISSING), value):
                object.__setattr__(self, "_stamp", next(_STAMPS))
        object.__setattr__(self, name, value)

    def __post_init__(self) -> None:
        object.__setattr__(self, "_checked", True)
        object.__setattr__(self, "_stamp", next(_STAMPS))


_SCENE_PARTS = ("camera", "lights", "materials", "objects", "render", "raytrace", "radiosity")
_STAMPS = itertools.count(1)   # edit stamps, unique in the process (next() is atomic)
_MISSING = object()


def _changes(old: Any, new: Any) -> bool:
    """True unless ``new`` equals ``old`` (a value that cannot be compared is a change)."""
    if old is new:
        return False
    try:
        return bool(old != new)
    except (TypeError, ValueError):  # e.g. numpy arrays
        return True


_SPECCED: dict[type, set[str]] = {}
# The preset loader's value check, (cls, key, value, source, where) -> canonical value. The
# package (shadelab/scene/__init__.py) sets it once preset.py is loaded: preset imports this
# module, so this module cannot import preset back without a cycle.
_VALIDATE: Any = None


@dataclass
class Camera(Checked):
    """A pinhole camera; ``fov_y`` is the full vertical field of view in degrees (widened in an
    image narrower than ``fit_aspect``: :func:`shadelab.scene.camera.tan_half_fov_y`)."""

    eye: Point3 = spec((0.0, 1.0, 5.0), "vec3", *COORD, doc="camera position, world units")
    target: Point3 = spec((0.0, 0.0, 0.0), "vec3", *COORD, doc="point looked at")
    up: Vec3 = spec((0.0, 1.0, 0.0), "vec3", *COORD, doc="up direction")
    fov_y: float = spec(45.0, "float", 1.0, 170.0, doc="vertical field of view, degrees")
    fit_aspect: float = spec(1.0, "float", 0.0, 8.0,
                             doc="narrowest width/height kept in view: a narrower image widens "
                                 "the vertical fov so fov_y's frame at this aspect fits side "
                                 "to side (0: never)")
    near: float = spec(0.1, "float", 1e-6, LENGTH_MAX, doc="near clipping distance, world units")


@dataclass
class Light(Checked):
    """A point, directional or spot light of RGB intensity ``Ip``.

    ``direction`` is the way the light travels (a directional light's rays; a spot's axis);
    the shading code turns it into ``to_light`` vectors, which point away from the surface.
    """

    kind: str = spec("point", "str", LIGHT_KINDS, doc="point | directional | spot")
    name: str = spec("", "str", None, doc="label shown in the viewer")
    enabled: bool = spec(True, "bool", doc="switch the light off without removing it")
    position: Point3 = spec((0.0, 5.0, 0.0), "vec3", *COORD, doc="point and spot lights")
    direction: Vec3 = spec((0.0, -1.0, 0.0), "vec3", *COORD, doc="directional and spot lights")
    Ip: Rgb = spec((1.0, 1.0, 1.0), "rgb", INTENSITY_MAX, doc="light intensity per RGB channel")
    attenuation: str = spec("none", "str", ATTENUATION_MODES, doc="none | inverse_square | lecture")
    c1: float = spec(1.0, "float", 0.0, COEFF_MAX, doc="f_att constant term")
    c2: float = spec(0.0, "float", 0.0, COEFF_MAX, doc="f_att linear term, per unit distance")
    c3: float = spec(0.0, "float", 0.0, COEFF_MAX, doc="f_att quadratic term, per distance squared")
    cone_angle: float = spec(30.0, "float", 0.0, 90.0, doc="spot half-angle, degrees")
    spot_exponent: float = spec(1.0, "float", 0.0, 1000.0, doc="spot falloff, cos^e")
    stand_in: bool = spec(False, "bool", doc="stands in for an emitting surface in the raster "
                          "and Whitted; the path tracer lights with that surface instead")


@dataclass
class Material(Checked):
    """The lecture's coefficients: ``kd`` scales the diffuse color ``Od``, ``ks`` the specular
    color ``Os``."""

    ka: float = spec(0.1, "float", 0.0, 1.0, doc="ambient-reflection coefficient")
    kd: float = spec(0.7, "float", 0.0, 1.0, doc="diffuse-reflection coefficient")
    ks: float = spec(0.0, "float", 0.0, 1.0, doc="specular-reflection coefficient")
    n: float = spec(10.0, "float", 0.0, 100000.0, doc="specular exponent")
    Od: Rgb = spec((1.0, 1.0, 1.0), "rgb01", doc="diffuse color")
    Os: Rgb = spec((1.0, 1.0, 1.0), "rgb01", doc="specular color")
    kt: float = spec(0.0, "float", 0.0, 1.0, doc="transmission coefficient")
    Ot: Rgb = spec((1.0, 1.0, 1.0), "rgb01", doc="transparency color (filtered model)")
    transparency: str = spec("interpolated", "str", TRANSPARENCY_MODELS, doc="raster model")
    kr: float = spec(-1.0, "float", -1.0, 1.0, doc="mirror reflection; -1 = use ks")
    ior: float = spec(1.5, "float", 1.0, 5.0, doc="index of refraction")
    emission: Rgb = spec((0.0, 0.0, 0.0), "rgb", INTENSITY_MAX,
                         doc="emitted radiance (radiosity, path tracing)")
    texture: str = spec("", "str", None, doc="'' | 'checker' | image path: modulates Od")
    texture_scale: float = spec(8.0, "float", 1e-6, 1e6, doc="texture repeats across [0,1] uv")
    texture_color2: Rgb = spec((0.1, 0.1, 0.1), "rgb01", doc="checker's second color")
    bump: str = spec("", "str", None, doc="'' | 'bumps' | height-map image path")
    bump_scale: float = spec(1.0, "float", 0.0, 100.0, doc="bump height scale")

    @property
    def mirror(self) -> float:
        """Reflection weight of the ray tracer: ``kr``, or the lecture's ``ks`` where unset."""
        return self.ks if self.kr < 0.0 else self.kr


@dataclass
class Object(Checked):
    """A trimesh primitive or a mesh file, placed by scale, then rotate (XYZ, degrees), then
    translate."""

    shape: str = spec("sphere", "str", SHAPES, doc="primitive or 'mesh'")
    name: str = spec("", "str", None, doc="label")
    material: str = spec("default", "str", None, doc="name of a [materials.X] table")
    path: str = spec("", "str", None, doc="mesh file (OBJ, PLY, STL, glTF/GLB), preset-relative")
    radius: float = spec(1.0, "float", 1e-9, LENGTH_MAX,
                         doc="sphere, cylinder, cone, capsule, torus")
    minor_radius: float = spec(0.25, "float", 1e-9, LENGTH_MAX, doc="torus tube radius")
    height: float = spec(1.0, "float", 1e-9, LENGTH_MAX, doc="cylinder, cone, capsule")
    extents: Vec3 = spec((1.0, 1.0, 1.0), "vec3", *COORD, doc="box edge lengths")
    size: float = spec(1.0, "float", 1e-9, LENGTH_MAX,
                       doc="plane edge length (xz plane, normal +y)")
    vertices: list = spec([], "vec3s", *COORD,
                          doc="quad corners, counter-clockwise seen from the front")
    subdivisions: int = spec(3, "int", 0, 7, doc="sphere: icosphere subdivision level")
    sections: int = spec(32, "int", 3, 1024, doc="cylinder, cone, torus, capsule sections")
    segments: int = spec(1, "int", 1, 512, doc="plane and quad: cells per edge")
    translate: Vec3 = spec((0.0, 0.0, 0.0), "vec3", *COORD, doc="world offset")
    rotate: Vec3 = spec((0.0, 0.0, 0.0), "vec3", *COORD, doc="XYZ Euler angles, degrees")
    scale: Vec3 = spec((1.0, 1.0, 1.0), "vec3", -SCALE_MAX, SCALE_MAX, doc="per-axis scale")
    normals: str = spec("crease", "str", NORMALS_MODES, doc="vertex normal rule")
    crease_angle: float = spec(30.0, "float", 0.0, 180.0, doc="crease mode: split above, degrees")
    cast_shadows: bool = spec(True, "bool", doc="casts shadow volumes / blocks shadow rays")
    weld: bool = spec(True, "bool", doc="mesh files: merge corners that share a position "
                      "(1e-6 of the bounding-box diagonal) so normals can be smooth")


@dataclass
class RenderSettings(Checked):
    """How the raster viewer draws the scene."""

    shading: str = spec("phong", "str", SHADING_MODES, doc="flat | gouraud | phong")
    specular: str = spec("phong", "str", SPECULAR_MODELS, doc="phong (R.V)^n | blinn (N.H)^n")
    shadows: str = spec("none", "str", ("none", "volumes"), doc="none | volumes")
    shadow_method: str = spec("zfail", "str", ("zfail", "zpass"), doc="stencil counting")
    visibility: str = spec("zbuffer", "str", ("zbuffer", "painter"), doc="hidden surfaces")
    exposure: float = spec(1.0, "float", 0.0, 1e6, doc="scale applied before display")
    background: Rgb = spec((0.0, 0.0, 0.0), "rgb", INTENSITY_MAX, doc="clear color, linear")
    show_volumes: bool = spec(False, "bool", doc="draw the shadow volumes, translucent")
    show_silhouettes: bool = spec(False, "bool", doc="highlight the casters' silhouette edges")
    stencil_heatmap: bool = spec(False, "bool", doc="overlay one light's stencil count")
    heatmap_light: int = spec(0, "int", 0, 15, doc="which light the stencil heat map shows")


@dataclass
class RaytraceSettings(Checked):
    """Whitted ray tracer and path tracer settings."""

    depth: int = spec(5, "int", 0, 64, doc="maximum recursion depth")
    spp: int = spec(1, "int", 1, 65536, doc="samples per pixel (stratified)")
    min_weight: float = spec(0.01, "float", 0.0, 1.0, doc="stop a ray below this weight")
    offset: float = spec(1e-3, "float", 0.0, LENGTH_MAX, doc="ray origin offset, scene-relative")
    fresnel: bool = spec(False, "bool", doc="weight reflection/refraction by Fresnel")
    sampler: str = spec("sobol", "str", ("sobol", "independent"),
                        doc="path tracer's samples: sobol (Owen-scrambled) | independent")


@dataclass
class RadiositySettings(Checked):
    """Radiosity meshing and solver settings."""

    patches: int = spec(400, "int", 1, 1000000, doc="target patch count")
    form_factors: str = spec("raycast", "str", ("hemicube", "raycast", "analytic"), doc="method")
    solver: str = spec("progressive", "str", RADIOSITY_SOLVERS, doc="solver")
    meshing: str = spec("discontinuity", "str", RADIOSITY_MESHINGS,
                        doc="uniform (a regular grid) | adaptive (solve, split where it "
                            "changes fast, solve again) | discontinuity (hidden cells "
                            "dropped, cells across the lights' shadow boundaries split)")
    hemicube_resolution: int = spec(128, "int", 4, 4096, doc="hemicube face resolution")
    iterations: int = spec(200, "int", 1, 1000000, doc="maximum solver iterations")
    tolerance: float = spec(1e-4, "float", 0.0, 1.0, doc="relative residual to stop at")
    ambient: bool = spec(True, "bool", doc="the viewer's shot-by-shot display adds "
                                          "progressive refinement's ambient estimate of the "
                                          "light not yet shot (Cohen et al. 1988); false: "
                                          "only the light shot so far")


@dataclass
class Scene(Checked):
    """Everything a renderer needs; ``base_dir`` resolves relative mesh and texture paths."""

    description: str = spec("", "str", None, doc="what this preset teaches")
    Ia: Rgb = spec((0.1, 0.1, 0.1), "rgb", INTENSITY_MAX, doc="ambient intensity")
    camera: Camera = field(default_factory=Camera)
    lights: list[Light] = field(default_factory=list)
    materials: dict[str, Material] = field(default_factory=dict)
    objects: list[Object] = field(default_factory=list)
    render: RenderSettings = field(default_factory=RenderSettings)
    raytrace: RaytraceSettings = field(default_factory=RaytraceSettings)
    radiosity: RadiositySettings = field(default_factory=RadiositySettings)
    schema_version: int = SCHEMA_VERSION
    name: str = field(default="", metadata={"internal": True})
    base_dir: str = field(default=".", metadata={"internal": True})

    def material_of(self, obj: Object) -> Material:
        return self.materials[obj.material]

    @property
    def version(self) -> int:
        """The scene's edit counter: it goes up once after any change to the scene or anything
        in it (a validated assignment to a field of the scene, its camera, settings, a light, a
        material or an object; a light, material or object added, removed or replaced), so a
        viewer sees an edit that no one announced. Reading it changes nothing else; a copy
        starts from the original's count."""
        nodes = (self, self.camera, self.render, self.raytrace, self.radiosity, *self.lights,
                 *self.materials.values(), *self.objects)
        signature = (tuple(self.materials), tuple(getattr(n, "_stamp", id(n)) for n in nodes))
        if signature != self.__dict__.get("_signature"):
            object.__setattr__(self, "_signature", signature)
            object.__setattr__(self, "_version", self.__dict__.get("_version", -1) + 1)
        return self.__dict__["_version"]

    def edit_key(self, *parts: str) -> tuple:
        """A key of some parts of the scene (``"camera"``, ``"lights"``, ``"materials"``,
        ``"objects"``, ``"render"``, ``"raytrace"``, ``"radiosity"``): it changes with any edit
        :attr:`version` counts in those parts, and with no other (work that does not depend on
        the camera keeps its key while the camera moves). A copy has its original's key."""
        key = []
        for part in parts:
            if part not in _SCENE_PARTS:
                raise ValueError(f"edit_key: unknown part '{part}' (expected one of "
                                 f"{', '.join(_SCENE_PARTS)})")
            value = getattr(self, part)
            if isinstance(value, dict):
                key.append(tuple(value))  # names too: a material renamed is an edit
                value = list(value.values())
            nodes = value if isinstance(value, list) else [value]
            key.append(tuple(getattr(n, "_stamp", id(n)) for n in nodes))
        return tuple(key)

    def active_lights(self) -> list[Light]:
        return [light for light in self.lights if light.enabled]


# ---------------------------------------------------------------- display (REPL, Jupyter)
# Readable reprs: the lecture's key fields of each part, then every field that differs from
# its default; ``_repr_html_`` draws the same as small tables in a notebook. Installed on the
# classes below their definitions (a dataclass writes its own __repr__ into each class).

_KEY_FIELDS = {"Camera": ("eye", "target", "fov_y"), "Light": ("kind", "position", "Ip"),
               "Material": ("ka", "kd", "ks", "n", "Od"), "Object": ("shape", "material")}
_MAX_ROWS = 50     # rows of an HTML table, lights and materials in the text
_TEXT_ROWS = 12    # objects listed by the text repr


def _fmt(value: Any) -> str:
    if isinstance(value, bool):
        return str(value)
    if isinstance(value, float):
        return f"{value:.4g}"
    if isinstance(value, tuple):
        return "(" + ", ".join(_fmt(v) for v in value) + ")"
    if isinstance(value, list):
        return "[" + ", ".join(_fmt(v) for v in value) + "]"
    return repr(value)


def _default_of(f: Any) -> Any:
    return f.default_factory() if f.default_factory is not MISSING else f.default


def _shown(obj: Any) -> list[tuple[str, Any]]:
    """(name, value) of the key fields and of every field off its default, in field order."""
    key = _KEY_FIELDS.get(type(obj).__name__, ())
    out = []
    for f in fields(obj):
        if "spec" not in f.metadata:
            continue
        value = getattr(obj, f.name)
        default = _default_of(f)
        same = (list(value) == list(default) if isinstance(value, (tuple, list))
                and isinstance(default, (tuple, list)) else value == default)
        if f.name in key or not same:
            out.append((f.name, value))
    return out


def _part_repr(self: Any) -> str:
    return f"{type(self).__name__}(" + ", ".join(f"{k}={_fmt(v)}" for k, v in _shown(self)) + ")"


def _esc(value: Any) -> str:
    import html

    return html.escape(value if isinstance(value, str) else _fmt(value))


def _table(header: list[str], rows: list[list[Any]], more: int = 0) -> str:
    head = "".join(f"<th style='text-align:left'>{_esc(h)}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td style='text-align:left'>{_esc(c)}</td>" for c in row)
                   + "</tr>" for row in rows)
    tail = (f"<tr><td colspan='{len(header)}'>… and {more} more</td></tr>" if more else "")
    return f"<table><thead><tr>{head}</tr></thead><tbody>{body}{tail}</tbody></table>"


def _part_html(self: Any) -> str:
    return (f"<b>{_esc(type(self).__name__)}</b>"
            + _table(["field", "value"], [[k, v] for k, v in _shown(self)]))


def _scene_summary(self: Scene) -> str:
    n_obj, n_light, n_mat = len(self.objects), len(self.lights), len(self.materials)
    return (f"{n_obj} object{'s' * (n_obj != 1)}, {n_light} light{'s' * (n_light != 1)}, "
            f"{n_mat} material{'s' * (n_mat != 1)}; shading {self.render.shading}, "
            f"specular {self.render.specular}, shadows {self.render.shadows}")


def _scene_repr(self: Scene) -> str:
    lines = [f"Scene {self.name or '(unnamed)'!r}: {_scene_summary(self)}"]
    if self.description:
        lines.append(f"  {self.description}")
    lines.append(f"  camera: {_part_repr(self.camera)}")
    lines.append(f"  Ia: {_fmt(tuple(self.Ia))}")
    lines += [f"  lights[{i}]: {_part_repr(light)}" for i, light in
              enumerate(self.lights[:_MAX_ROWS])]
    lines += [f"  materials[{name!r}]: {_part_repr(m)}" for name, m in
              list(self.materials.items())[:_MAX_ROWS]]
    lines += [f"  objects[{i}]: {_part_repr(o)}" for i, o in enumerate(self.objects[:_TEXT_ROWS])]
    hidden = max(0, len(self.objects) - _TEXT_ROWS)
    if hidden:
        lines.append(f"  ... and {hidden} more objects")
    return "\n".join(lines)


def _scene_html(self: Scene) -> str:
    parts = [f"<b>Scene {_esc(self.name or '(unnamed)')}</b>: {_esc(_scene_summary(self))}"]
    if self.description:
        parts.append(f"<br><i>{_esc(self.description)}</i>")
    cam = self.camera
    parts.append("<br>camera: eye " + _esc(tuple(cam.eye)) + ", target " + _esc(tuple(cam.target))
                 + f", fov_y {_esc(cam.fov_y)}°; Ia {_esc(tuple(self.Ia))}")
    lights = [[i, light.kind, light.name, light.enabled, light.position, light.direction,
               light.Ip, light.attenuation] for i, light in enumerate(self.lights)]
    parts.append(_table(["lights", "kind", "name", "enabled", "position", "direction", "Ip",
                         "attenuation"], lights[:_MAX_ROWS], max(0, len(lights) - _MAX_ROWS)))
    mats = [[name, m.ka, m.kd, m.ks, m.n, m.Od, m.Os, m.kt, m.emission]
            for name, m in self.materials.items()]
    parts.append(_table(["materials", "ka", "kd", "ks", "n", "Od", "Os", "kt", "emission"],
                        mats[:_MAX_ROWS], max(0, len(mats) - _MAX_ROWS)))
    objs = [[i, o.name, o.shape, o.material, o.translate, o.normals]
            for i, o in enumerate(self.objects)]
    parts.append(_table(["objects", "name", "shape", "material", "translate", "normals"],
                        objs[:_MAX_ROWS], max(0, len(objs) - _MAX_ROWS)))
    return "".join(parts)


for _cls in (Camera, Light, Material, Object, RenderSettings, RaytraceSettings,
             RadiositySettings):
    _cls.__repr__ = _part_repr
    _cls._repr_html_ = _part_html
Scene.__repr__ = _scene_repr
Scene._repr_html_ = _scene_html
