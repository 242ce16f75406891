"""The Python API: presets, renders, the probe and the viewer from a script or a notebook.

Everything here is re-exported from :mod:`shadelab` (``shadelab.render(...)``) and imported
only on first use, so ``import shadelab`` stays cheap and GL-free. Bad input raises
:class:`~shadelab.errors.ShadeLabError` with the same one-line message the CLI prints.

Examples
--------
>>> import shadelab
>>> scene = shadelab.load_preset("cornell", overrides={"materials.white.kd": 0.8})
>>> scene.materials["red"].kd = 0.5          # validated as the TOML is
>>> image = shadelab.render(scene, size=(256, 256), shading="gouraud")
>>> image.array.shape, image.array.dtype
((256, 256, 3), dtype('float32'))
>>> image.save("cornell.png")                # sRGB PNG; ".npy" keeps linear float32
"""

from __future__ import annotations

import copy
import io
from collections.abc import Mapping, Sequence
from pathlib import Path
from typing import Any

import numpy as np

from shadelab.errors import ShadeLabError
from shadelab.scene.model import SHADING_MODES, SPECULAR_MODELS, Scene

__all__ = ["PIPELINES", "Image", "ShadeLabError", "load_preset",  # noqa: F822  (PIPELINES:
           "save_preset", "list_presets", "render", "probe", "show"]  # from the registry)



def __getattr__(name: str):
    """``PIPELINES`` and ``DEFAULT_SIZES`` are read from :mod:`shadelab.pipelines` when asked
    for, so a pipeline registered later (a plugin, a test) is listed too."""
    from shadelab import pipelines

    if name == "PIPELINES":
        #: What :func:`render` can run: ``raster`` (the GL z-buffer with the scene's shading),
        #: then every registered pipeline (painter, gouraud, phong, flat, radiosity, ...).
        return pipelines.all_names()
    if name == "DEFAULT_SIZES":
        return {n: tuple(pipelines.get(n).default_size) for n in pipelines.all_names()}
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


# ---------------------------------------------------------------- images


# ---------------------------------------------------------------- argument checks
# Every public function checks its arguments as a preset is checked: a wrong type or value is
# one ShadeLabError line naming the argument (never a builtin error from deep inside).

FORM_FACTORS = ("hemicube", "raycast", "analytic")


def _is_int(value: Any) -> bool:
    return isinstance(value, (int, np.integer)) and not isinstance(value, (bool, np.bool_))


def _check_int(name: str, value: Any, lo: int | None = None,
               hi: int | None = None) -> int | None:
    """None, or an int in [lo, hi] (no bound where None); anything else is one line."""
    if value is None:
        return None
    expected = (f"an integer in [{lo}, {hi}]" if hi is not None and lo is not None
                else f"an integer >= {lo}" if lo is not None else "an integer")
    if not _is_int(value) or (lo is not None and value < lo) or (hi is not None
                                                                 and value > hi):
        raise ShadeLabError(f"{name} {value!r}: expected {expected}")
    return int(value)


def _check_choice(name: str, value: Any, choices) -> str | None:
    if value is None:
        return None
    if not isinstance(value, str) or value not in choices:
        raise ShadeLabError(f"{name} {value!r}: expected one of {', '.join(choices)}")
    return value


def _check_bool(name: str, value: Any, optional: bool = True) -> bool | None:
    if value is None and optional:
        return None
    if not isinstance(value, (bool, np.bool_)):
        raise ShadeLabError(f"{name} {value!r}: expected True or False")
    return bool(value)


def _check_path(name: str, value: Any, optional: bool = False) -> Path | None:
    if value is None and optional:
        return None
    if not isinstance(value, (str, Path)) or not str(value).strip():
        raise ShadeLabError(f"{name} {value!r}: expected a file name (str or pathlib.Path)")
    if "\x00" in str(value):
        raise ShadeLabError(f"{name} {value!r}: has a NUL character in its name")
    return Path(value)


class Image:
    """A rendered image: linear radiance with its display exposure.

    Parameters
    ----------
    array : array_like, shape (H, W, 3)
        Linear RGB radiance (row 0 at the top); stored as C-contiguous float32.
    exposure : float, optional
        Scale applied before sRGB encoding for display and PNG output (the scene's
        ``render.exposure``); ``array`` itself is never scaled.
    info : dict, optional
        What made the image (pipeline, shading, size, the renderer's statistics).

    Attributes
    ----------
    array : numpy.ndarray, shape (H, W, 3), float32
        Linear radiance, as ``--npy`` writes it.
    """

    def __init__(self, array: Any, exposure: float = 1.0, info: dict | None = None):
        try:
            a = np.ascontiguousarray(array, dtype=np.float32)
        except (TypeError, ValueError):
            raise ShadeLabError(f"image: expected an (H, W, 3) array of numbers, got "
                                f"{type(array).__name__}") from None
        if a.ndim != 3 or a.shape[2] != 3:
            raise ShadeLabError(f"image: expected an (H, W, 3) array, got shape {a.shape}")
        if isinstance(exposure, (bool, np.bool_)) or not isinstance(
                exposure, (int, float, np.integer, np.floating)) or not np.isfinite(exposure) \
                or exposure < 0:
            raise ShadeLabError(f"exposure={exposure!r}: expected a finite number >= 0")
        if info is not None and not isinstance(info, Mapping):
            raise ShadeLabError(f"info={info!r}: expected a dict")
        self.array = a
        self.exposure = float(exposure)
        self.info = dict(info or {})

    @property
    def shape(self) -> tuple[int, int, int]:
        """(H, W, 3)."""
        return self.array.shape

    @property
    def size(self) -> tuple[int, int]:
        """(width, height) in pixels, as ``--size`` reads."""
        return self.array.shape[1], self.array.shape[0]

    def __array__(self, dtype=None, copy=None):
        return self.array if dtype is None else self.array.astype(dtype)

    def to_srgb8(self) -> np.ndarray:
        """sRGB-encoded (H, W, 3) uint8 after ``exposure``, as the PNG holds it."""
        from shadelab.shading.conventions import to_srgb8

        return to_srgb8(self.array, self.exposure)

    def save(self, path: str | Path) -> Path:
        """Write ``.png`` (sRGB 8-bit, with text chunks saying what made it and an sRGB chunk),
        ``.exr`` (linear float32 RGB, the array itself) or ``.npy`` (float32 linear radiance).

        Returns
        -------
        pathlib.Path
            The file written.
        """
        from shadelab.imageio import check_image_name, check_writable, write_npy, write_png

        path = _check_path("path", path)
        suffix = path.suffix.lower()
        if suffix not in (".png", ".exr", ".npy"):
            raise ShadeLabError(f"save '{path}': expected a .png or .npy file name, or .exr "
                                "for linear float RGB")
        check_writable(str(path), "save")
        if suffix == ".npy":
            write_npy(str(path), self.array)
        else:
            check_image_name(str(path), "save")
            write_png(str(path), self.array, self.exposure, self.metadata())
        return path

    def metadata(self) -> dict[str, str]:
        """The text a saved PNG (or EXR header) carries: preset, overrides, pipeline and
        shading where :attr:`info` has them, the ShadeLab version and ``Software``."""
        from shadelab.imageio import image_metadata

        fields = {key: self.info.get(key) for key in ("preset", "overrides", "pipeline",
                                                       "shading")}
        if isinstance(fields["overrides"], Mapping):
            fields["overrides"] = _override_items(fields["overrides"])
        return image_metadata(**{k: v for k, v in fields.items() if v is not None})

    def _repr_png_(self) -> bytes:
        """Jupyter's inline display: the sRGB PNG bytes."""
        from PIL import Image as PILImage

        buffer = io.BytesIO()
        PILImage.fromarray(self.to_srgb8()).save(buffer, format="PNG")
        return buffer.getvalue()

    def __repr__(self) -> str:
        w, h = self.size
        what = ", ".join(f"{k}={self.info[k]}" for k in ("pipeline", "shading") if k in self.info)
        return f"<shadelab.Image {w}x{h}{', ' + what if what else ''}>"


# ---------------------------------------------------------------- presets


def list_presets() -> list[str]:
    """Names of the presets shipped with ShadeLab, sorted."""
    from shadelab.scene.preset import list_presets as names

    return names()


def _override_items(overrides: Mapping[str, Any] | Sequence[str] | None) -> list[str]:
    """``{"a.b": 1}`` or ``["a.b=1"]`` -> ``--set`` items (TOML literals for dict values)."""
    if overrides is None:
        return []
    if isinstance(overrides, str):
        return [overrides]
    if not isinstance(overrides, (Mapping, Sequence)) or isinstance(overrides, bytes):
        raise ShadeLabError(f"overrides={overrides!r}: expected a dict of dotted keys, or a "
                            "list of 'KEY=VALUE' strings")
    if isinstance(overrides, Mapping):
        import tomli_w

        items = []
        for key, value in overrides.items():
            if hasattr(value, "tolist"):  # numpy scalars and arrays
                value = value.tolist()
            if isinstance(value, tuple):
                value = list(value)
            if not isinstance(key, str):
                raise ShadeLabError(f"overrides: key {key!r}: expected a dotted key string")
            try:
                if isinstance(value, Mapping) or value is None:  # a table, not a value
                    raise TypeError
                literal = tomli_w.dumps({"v": value}).split("=", 1)[1].strip()
            except (TypeError, ValueError, IndexError):
                raise ShadeLabError(f"overrides '{key}': cannot use a {type(value).__name__} "
                                    "(expected a number, bool, string or list)") from None
            items.append(f"{key}={literal}")
        return items
    for item in overrides:
        if not isinstance(item, str):
            raise ShadeLabError(f"overrides: item {item!r}: expected a 'KEY=VALUE' string")
    return list(overrides)


def load_preset(name_or_path: str | Path,
                overrides: Mapping[str, Any] | Sequence[str] | None = None) -> Scene:
    """Load a preset, apply overrides and validate it.

    Parameters
    ----------
    name_or_path : str or pathlib.Path
        A preset name (``shadelab.list_presets()``) or a path to a TOML file.
    overrides : dict or list of str, optional
        Dotted keys as ``--set`` takes them: ``{"materials.white.kd": 0.5, "lights.0.Ip":
        (2, 2, 2)}`` or ``["materials.white.kd=0.5"]``. Validated exactly as ``--set`` is.

    Returns
    -------
    Scene
        Mutable plain data. Assigning a field validates it against the preset schema
        (``scene.materials["white"].kd = 1.5`` raises ``ShadeLabError``).
    """
    from shadelab.scene.preset import load_preset as load

    _check_path("name_or_path", name_or_path)
    return load(str(name_or_path), _override_items(overrides))


def save_preset(scene: Scene, path: str | Path) -> None:
    """Write ``scene`` as a TOML preset (round-trips exactly through :func:`load_preset`)."""
    from shadelab.scene.preset import save_preset as save

    if not isinstance(scene, Scene):
        raise ShadeLabError(f"scene: expected a Scene (from load_preset), got "
                            f"{type(scene).__name__}")
    save(_scene(scene), _check_path("path", path))  # nothing a preset would refuse is saved


def _scene(scene: Scene | str | Path) -> Scene:
    """A preset name loaded, or a Scene checked as a preset would be (an edit in Python that
    a preset would refuse — a 17th light, a zero scale, the eye on the target — is one line)."""
    if isinstance(scene, Scene):
        from shadelab.scene.preset import check_scene

        check_scene(scene, scene.name or "scene")
        return scene
    if isinstance(scene, (str, Path)):
        return load_preset(scene)
    raise ShadeLabError(f"expected a Scene or a preset name, got {type(scene).__name__}")


def _size(size: Any, pipeline: str) -> tuple[int, int]:
    from shadelab.imageio import parse_size

    if size is None:
        from shadelab import pipelines

        return tuple(pipelines.get(pipeline).default_size)
    if isinstance(size, str):
        return parse_size(size)
    if isinstance(size, (int, np.integer)) and not isinstance(size, bool):
        return parse_size(str(int(size)))
    try:
        w, h = size
    except (TypeError, ValueError):
        raise ShadeLabError(f"size {size!r}: expected (width, height), N or 'WxH'") from None
    if not (_is_int(w) and _is_int(h)):
        raise ShadeLabError(f"size {size!r}: expected (width, height) integers")
    return parse_size(f"{int(w)}x{int(h)}")


# ---------------------------------------------------------------- rendering


def render(scene: Scene | str, size: Any = None, shading: str | None = None,
           pipeline: str = "raster", *, specular: str | None = None, depth: int | None = None,
           spp: int | None = None, seed: int = 0, fresnel: bool | None = None,
           patches: int | None = None, form_factors: str | None = None,
           solver: str | None = None, backend: str = "auto", workers: int = 1,
           progress: bool = False) -> Image:
    """Render a scene headless with any of ShadeLab's pipelines.

    Parameters
    ----------
    scene : Scene or str
        A scene (from :func:`load_preset`) or a preset name. It is not modified.
    size : (int, int) or int or str, optional
        (width, height) in pixels, ``N`` for a square or ``"WxH"``; each side in [1, 16384].
        Default: the CLI's size for the pipeline (800x600 raster, 512x512 ray tracing and
        radiosity, 256x256 path tracing).
    shading : {"flat", "gouraud", "phong"}, optional
        ``raster`` and ``painter`` only; default the scene's ``render.shading``.
    pipeline : str
        A name of :func:`shadelab.pipelines.names` or ``raster``.
        ``raster``: GL z-buffer with the scene's shading (``shadelab render``); ``gouraud``,
        ``phong``, ``flat``: the same with that shading; ``painter``: list priority
        (``--visibility painter``); ``raytrace``: Whitted (``shadelab raytrace``);
        ``pathtrace``: Monte Carlo reference (``shadelab pathtrace``); ``radiosity``: solved
        patches shown Gouraud-shaded (``shadelab radiosity``).
    specular : {"phong", "blinn"}, optional
        Raster pipelines: (R.V)^n or (N.H)^n; default the scene's ``render.specular``.
    depth, spp, fresnel : optional
        Ray tracing: recursion depth, samples per pixel (path tracing default 64), Fresnel.
    seed : int
        Path tracing random seed.
    patches, form_factors, solver : optional
        Radiosity: target patch count, ``hemicube`` or ``raycast``, the solver.
    backend : {"auto", "embree", "bvh"}
        Ray casting backend of the CPU tracers.
    workers : int
        Processes tracing tiles in parallel (CPU tracers).
    progress : bool
        Show a tqdm bar for the offline pipelines.

    Returns
    -------
    Image
        ``.array`` is float32 linear radiance, shape (H, W, 3), row 0 at the top, aligned
        pixel for pixel across pipelines; ``.info`` holds the pipeline and its statistics.
    """
    from shadelab import pipelines
    from shadelab.cli.raytrace import MAX_SEED
    from shadelab.raytrace import BACKENDS
    from shadelab.scene.model import RADIOSITY_SOLVERS

    scene = _scene(scene)
    if not isinstance(pipeline, str):
        raise ShadeLabError(f"pipeline={pipeline!r}: expected a pipeline name (str)")
    _check_choice("shading", shading, SHADING_MODES)
    _check_choice("specular", specular, SPECULAR_MODELS)
    _check_int("depth", depth)  # types here; ranges as the CLI's (_check_counts below)
    _check_int("spp", spp)
    if seed is None or _check_int("seed", seed, 0, MAX_SEED) is None:
        raise ShadeLabError(f"seed={seed!r}: expected an integer in [0, 2**63 - 1]")
    _check_bool("fresnel", fresnel)
    _check_int("patches", patches, 1)
    _check_choice("form_factors", form_factors, FORM_FACTORS)
    _check_choice("solver", solver, RADIOSITY_SOLVERS)
    _check_choice("backend", backend, BACKENDS)
    if _check_int("workers", workers) is None:
        raise ShadeLabError("workers=None: expected an integer in [1, 64]")
    _check_bool("progress", progress, optional=False)
    chosen = pipelines.get(pipeline)
    accepts = set(getattr(chosen, "options", ()))
    if shading is not None and shading not in SHADING_MODES:
        raise ShadeLabError(f"shading '{shading}': expected one of {', '.join(SHADING_MODES)}")
    if shading is not None and "shading" not in accepts:
        raise ShadeLabError(f"shading '{shading}': applies to the raster and painter "
                            f"pipelines, not {pipeline}")
    if specular is not None and specular not in SPECULAR_MODELS:
        raise ShadeLabError(f"specular '{specular}': expected one of "
                            f"{', '.join(SPECULAR_MODELS)}")
    wh = _size(size, pipeline)
    exposure = scene.render.exposure
    info: dict[str, Any] = {"pipeline": pipeline, "size": wh}
    given = {"shading": shading, "specular": specular, "depth": depth, "spp": spp,
             "seed": seed, "fresnel": fresnel, "patches": patches,
             "form_factors": form_factors, "solver": solver, "backend": backend,
             "workers": workers}
    options = {k: v for k, v in given.items() if k in accepts and v is not None}
    if getattr(chosen, "raster", None) is None:  # the CPU pipelines: one set of checks
        from shadelab.cli.raytrace import _check_counts

        _check_counts(depth if "depth" in accepts else None, spp, workers)
    chosen.check(scene, scene.name or "scene")
    from shadelab.progress import run_to_end

    last = run_to_end(chosen.run(scene, wh, **options), desc=chosen.name,
                      show=progress and getattr(chosen, "raster", None) is None)
    info.update(chosen.info(last, options))
    return Image(chosen.image(last, wh, **options), exposure, info)


# ---------------------------------------------------------------- the probe


def _vec(v: Any) -> tuple[float, ...]:
    return tuple(float(c) for c in np.asarray(v, dtype=np.float64).reshape(-1))


def _shadow_value(shadow) -> float | list[float]:
    values = np.asarray(shadow, dtype=np.float64).reshape(-1)
    return float(values[0]) if np.ptp(values) == 0.0 else [float(v) for v in values]


def probe(scene: Scene | str, pixel: tuple[int, int], size: Any = (800, 600),
          shading: str | None = None, specular: str | None = None) -> dict | None:
    """The lecture's terms at the surface point a pixel shows (the viewer's probe, as data).

    Parameters
    ----------
    scene : Scene or str
        A scene or a preset name.
    pixel : (int, int)
        (x, y) of a ``size`` image, row 0 at the top (as :func:`render` lays it out).
    size : (int, int) or int or str
        The image the pixel belongs to; default 800x600 (the raster default).
    shading, specular : str, optional
        As :func:`render`; default the scene's.

    Returns
    -------
    dict or None
        None when the pixel shows the background. Otherwise plain Python data (JSON-ready):
        ``pixel``, ``shading``, ``specular``, ``object`` (index into ``scene.objects``),
        ``material`` (name), ``face``, ``t`` (ray distance, world units), ``point`` (3,),
        ``normal`` (3,) unit N facing the viewer, ``to_eye`` (3,) unit V, ``emission`` (3,),
        ``ambient`` (3,) Ia ka Od, ``lights``: one dict per enabled light with ``to_light``
        (3,) unit L, ``reflected`` (3,) R (or H for Blinn), ``distance``, ``f_att``,
        ``clamped`` (the lecture's min(., 1) active), ``spot``, ``shadow`` S (a number, or
        [r, g, b] where transparent casters filter it),
        ``diffuse`` (3,) and ``specular`` (3,) radiance; ``total`` (3,) the equation at the
        point and ``reference`` (3,) what the shading mode computes at this pixel (linear
        RGB, before exposure).
    """
    scene = _scene(scene)
    wh = _size(size, "raster")
    try:
        x, y = pixel
    except (TypeError, ValueError):
        raise ShadeLabError(f"pixel {pixel!r}: expected (x, y)") from None
    if not (_is_int(x) and _is_int(y)):
        raise ShadeLabError(f"pixel {pixel!r}: expected (x, y) integers")
    x, y = int(x), int(y)
    if not (0 <= x < wh[0] and 0 <= y < wh[1]):
        raise ShadeLabError(f"pixel ({x}, {y}): outside the {wh[0]}x{wh[1]} image")
    if shading is not None and shading not in SHADING_MODES:
        raise ShadeLabError(f"shading '{shading}': expected one of {', '.join(SHADING_MODES)}")
    if specular is not None and specular not in SPECULAR_MODELS:
        raise ShadeLabError(f"specular '{specular}': expected one of "
                            f"{', '.join(SPECULAR_MODELS)}")
    from shadelab.lab.probe import probe as run_probe  # pure numpy, no GL

    result = run_probe(scene, wh, (x, y), shading, specular)
    if result is None:
        return None
    terms = result.terms
    lights = []
    for i, term in enumerate(terms.lights):
        lights.append({"to_light": _vec(term.to_light), "reflected": _vec(result.reflected(i)),
                       "distance": float(term.distance), "f_att": float(term.f_att),
                       "clamped": bool(term.clamp_active), "spot": float(term.spot),
                       "shadow": _shadow_value(term.shadow), "diffuse": _vec(term.diffuse),
                       "specular": _vec(term.specular)})
    return {"pixel": (x, y), "shading": result.shading, "specular": result.specular,
            "object": int(result.hit.mesh.index), "material": result.hit.mesh.material,
            "face": int(result.hit.face), "t": float(result.hit.t),
            "point": _vec(result.point), "normal": _vec(result.normal),
            "to_eye": _vec(result.to_eye), "emission": _vec(terms.emission),
            "ambient": _vec(terms.ambient), "lights": lights, "total": _vec(terms.total),
            "reference": _vec(result.reference)}


# ---------------------------------------------------------------- the viewer


def show(scene: Scene | str, window: Any = (1600, 900), frames: int = 0,
         screenshot: str | Path | None = None, autosave: bool = False) -> int:
    """Open the interactive viewer on ``scene`` (blocks until the window is closed).

    Parameters
    ----------
    scene : Scene or str
        The scene to view; the viewer edits a copy, ``scene`` itself is left as it is.
    window : (int, int) or str
        Window size in pixels.
    frames : int
        Quit after this many frames (0: run until closed).
    screenshot : str or pathlib.Path, optional
        Write a PNG of the window at exit.
    autosave : bool
        Save the session like ``shadelab view`` does (off: a script's scene does not replace
        the user's autosaved session).

    Returns
    -------
    int
        The viewer's exit code (0).
    """
    import os

    from shadelab.ui.display import NO_DISPLAY

    scene = _scene(scene)
    _check_int("frames", frames, 0)
    if frames is None:
        raise ShadeLabError("frames=None: expected an integer >= 0")
    _check_path("screenshot", screenshot, optional=True)
    _check_bool("autosave", autosave, optional=False)
    wh = _size(window, "raster")
    if not os.environ.get("DISPLAY") and not os.environ.get("WAYLAND_DISPLAY"):
        raise ShadeLabError(NO_DISPLAY)
    from shadelab.imageio import check_writable

    shot = str(screenshot) if screenshot else ""
    check_writable(shot or None, "screenshot")
    wh = _size(window, "raster")
    from shadelab.geometry.mesh import scene_meshes

    scene = copy.deepcopy(scene)
    scene_meshes(scene)  # a broken mesh file fails here, with its one-line reason
    from shadelab.lab.state import AppState
    from shadelab.ui.app import ViewerOptions, run_viewer

    state = AppState.from_scene(scene, scene.name or "script")
    options = ViewerOptions(frames=frames, screenshot=shot, window_size=wh, autosave=autosave)
    return int(run_viewer(state, options) or 0)
