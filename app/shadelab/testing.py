"""Image assertions for anyone's tests: ShadeLab's golden-image machinery, and a pytest plugin.

:func:`assert_images_close` compares two images the way ShadeLab's own golden tests do: both
are encoded to sRGB 8-bit and a named threshold bounds the share of pixels that differ by more
than a few levels and the RMSE. On failure the actual image, the reference and a magnified
difference image are written to an output folder and named in the message.

The pytest plugin (registered through the ``pytest11`` entry point, so a course's ``pytest``
finds it once ShadeLab is installed) adds:

- ``--shadelab-regenerate`` (or ``SHADELAB_REGENERATE=1``): write the reference images instead
  of comparing them;
- the fixture ``shadelab_images``: ``shadelab_images.check(name, image, threshold="golden")``
  compares against ``golden/<name>.png`` beside the test file and writes failures to
  ``_output/`` there (the layout of ShadeLab's own ``tests/``);
- :func:`render_with_shaders`: render with a student's GLSL include in place of ShadeLab's.

Examples
--------
In a course's ``test_lighting.py``::

    import shadelab
    from shadelab.testing import render_with_shaders

    def test_student_lighting(shadelab_images):
        image = render_with_shaders("lecture", {"lighting": "student/lighting.glsl"},
                                    size=(128, 128), shading="phong")
        shadelab_images.check("lecture-phong", image)
"""

from __future__ import annotations

import contextlib
import os
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from shadelab.errors import ShadeLabError

REGENERATE_ENV = "SHADELAB_REGENERATE"
OUTPUT_ENV = "SHADELAB_IMAGE_OUTPUT"


@dataclass(frozen=True)
class Threshold:
    """How close two sRGB 8-bit images must be.

    Attributes
    ----------
    pixel : int
        Levels (of 255) a channel may differ by before the pixel counts as differing.
    max_share : float
        Share of pixels, in [0, 1], allowed to differ by more than ``pixel``.
    max_rmse : float
        Root mean squared difference over every channel, in 8-bit levels.
    """

    pixel: int
    max_share: float
    max_rmse: float

    def __post_init__(self) -> None:
        import math

        def number(value) -> bool:
            return isinstance(value, (int, float)) and not isinstance(value, bool) \
                and math.isfinite(value)

        if not (isinstance(self.pixel, int) and not isinstance(self.pixel, bool)
                and 0 <= self.pixel <= 255):
            raise ShadeLabError(f"threshold pixel {self.pixel!r}: expected an int in [0, 255]")
        if not (number(self.max_share) and 0.0 <= self.max_share <= 1.0):
            raise ShadeLabError(f"threshold max_share {self.max_share!r}: expected a number "
                                "in [0, 1]")
        if not (number(self.max_rmse) and 0.0 <= self.max_rmse <= 255.0):
            raise ShadeLabError(f"threshold max_rmse {self.max_rmse!r}: expected a number in "
                                "[0, 255]")


#: Named thresholds. ``golden``: ShadeLab's own golden images (blessed on Mesa llvmpipe; a GPU
#: driver rounds differently on a few edge pixels); ``exact``: identical images only;
#: ``driver``: different GL drivers or platforms (rasterization rules differ on edges);
#: ``noisy``: Monte Carlo images of the same seed on other hardware.
THRESHOLDS: dict[str, Threshold] = {
    "exact": Threshold(pixel=0, max_share=0.0, max_rmse=0.0),
    "golden": Threshold(pixel=2, max_share=0.001, max_rmse=1.0),
    "driver": Threshold(pixel=8, max_share=0.01, max_rmse=3.0),
    "noisy": Threshold(pixel=16, max_share=0.05, max_rmse=8.0),
}


def threshold_of(threshold: str | Threshold) -> Threshold:
    if isinstance(threshold, Threshold):
        return threshold
    if not isinstance(threshold, str):
        raise ShadeLabError(f"threshold {threshold!r}: expected one of "
                            f"{', '.join(THRESHOLDS)} or a Threshold")
    if threshold not in THRESHOLDS:
        raise ShadeLabError(f"threshold '{threshold}': expected one of "
                            f"{', '.join(THRESHOLDS)} or a Threshold")
    return THRESHOLDS[threshold]


def regenerate_requested() -> bool:
    """True when ``SHADELAB_REGENERATE`` is set to something other than '', 0, false, no."""
    return os.environ.get(REGENERATE_ENV, "").strip().lower() not in ("", "0", "false", "no")


def as_srgb8(image: Any, exposure: float | None = None):
    """(H, W, 3) uint8 sRGB from an ``Image``, a float linear array, a uint8 array or a path.

    Float arrays are linear radiance and are encoded with ``exposure`` (default 1); an
    ``Image`` uses its own exposure unless one is given; uint8 arrays are taken as sRGB.
    """
    import numpy as np

    from shadelab.shading.conventions import to_srgb8

    exposure = _exposure(exposure)
    if isinstance(image, (str, Path)):
        return _read_png(Path(image))
    if hasattr(image, "array") and hasattr(image, "exposure"):
        _check_finite(image.array)
        return to_srgb8(image.array, image.exposure if exposure is None else exposure)
    try:
        a = np.asarray(image)
    except (TypeError, ValueError) as exc:
        raise ShadeLabError(f"image: not an array ({exc})") from None
    if a.ndim != 3 or a.shape[2] not in (3, 4):
        raise ShadeLabError(f"image: expected an (H, W, 3) array, got shape {a.shape}")
    a = a[..., :3]
    if a.dtype == np.uint8:
        return np.ascontiguousarray(a)
    if a.dtype.kind != "f":
        raise ShadeLabError(f"image: expected uint8 (sRGB) or float (linear radiance), got "
                            f"{a.dtype}")
    _check_finite(a)
    return to_srgb8(a.astype(np.float32), 1.0 if exposure is None else exposure)


def _exposure(exposure: Any) -> float | None:
    import math

    if exposure is None:
        return None
    if isinstance(exposure, bool) or not isinstance(exposure, (int, float)) \
            or not math.isfinite(exposure) or exposure <= 0:
        raise ShadeLabError(f"exposure {exposure!r}: expected a finite number > 0")
    return float(exposure)


def _check_finite(a) -> None:
    """NaN or Inf radiance is a wrong image, never one equal to its reference."""
    import numpy as np

    bad = int(np.count_nonzero(~np.isfinite(a)))
    if bad:
        raise AssertionError(f"image: {bad} NaN or infinite values (radiance must be finite)")


def _read_png(path: Path):
    """An image file as sRGB uint8, inside Pillow's guards: missing, fake, truncated and
    decompression-bomb files are one line."""
    import numpy as np
    from PIL import Image as PILImage

    if not path.is_file():
        raise ShadeLabError(f"{path}: image file not found")
    try:
        with PILImage.open(path) as im:
            return np.asarray(im.convert("RGB"))
    except PILImage.DecompressionBombError as exc:
        raise ShadeLabError(f"{path}: image too large to read ({exc})") from None
    except (OSError, ValueError, SyntaxError) as exc:  # UnidentifiedImageError is an OSError
        reason = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        raise ShadeLabError(f"{path}: not a readable image ({reason})") from None


def _save(array, path: Path) -> None:
    """Write a PNG through a temporary file beside it: a full disk or a read-only folder is
    one line, and never leaves a half-written reference."""
    import tempfile

    from PIL import Image as PILImage

    if path.is_dir():
        raise ShadeLabError(f"{path}: is a folder, not an image file")
    tmp = None
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        fd, tmp = tempfile.mkstemp(prefix=f".{path.stem}.", suffix=".png.tmp", dir=path.parent)
        with os.fdopen(fd, "wb") as out:
            PILImage.fromarray(array).save(out, format="PNG")
        os.replace(tmp, path)
        tmp = None
    except OSError as exc:
        raise ShadeLabError(f"{path}: cannot write ({exc.strerror or exc})") from None
    finally:
        if tmp is not None:
            with contextlib.suppress(OSError):
                os.unlink(tmp)


def assert_images_close(actual: Any, expected: Any, threshold: str | Threshold = "golden", *,
                        name: str | None = None, output_dir: str | Path | None = None,
                        exposure: float | None = None, regenerate: bool | None = None) -> dict:
    """Assert that two images agree within a named threshold (sRGB 8-bit comparison).

    Parameters
    ----------
    actual : Image, array_like or path
        What was rendered: a :class:`shadelab.Image`, linear float (H, W, 3), sRGB uint8
        (H, W, 3) or a PNG path.
    expected : Image, array_like or path
        The reference, in the same forms. A path to a PNG that does not exist yet is written
        from ``actual`` when regenerating.
    threshold : str or Threshold
        A name from :data:`THRESHOLDS` (``exact``, ``golden``, ``driver``, ``noisy``).
    name : str, optional
        Names the failure images; default the reference file's stem, or ``image``.
    output_dir : str or pathlib.Path, optional
        Where ``<name>_img.png``, ``<name>_ref.png`` and ``<name>_diff.png`` (the difference
        x16) go on failure; default ``$SHADELAB_IMAGE_OUTPUT`` or ``./shadelab-image-diffs``.
    exposure : float, optional
        Exposure applied to linear inputs before sRGB encoding.
    regenerate : bool, optional
        Write ``actual`` over ``expected`` (a path) instead of comparing; default from
        ``SHADELAB_REGENERATE``.

    Returns
    -------
    dict
        ``share`` (of pixels beyond ``pixel`` levels), ``rmse`` (8-bit levels),
        ``max_diff`` (levels), or ``{"regenerated": path}``.

    Raises
    ------
    AssertionError
        When the images differ in size or beyond the threshold.
    """
    import numpy as np

    limit = threshold_of(threshold)
    img = as_srgb8(actual, exposure)
    ref_path = Path(expected) if isinstance(expected, (str, Path)) else None
    name = name or (ref_path.stem if ref_path else "image")
    if regenerate is None:
        regenerate = regenerate_requested()
    if ref_path is not None and regenerate:
        _save(img, ref_path)
        return {"regenerated": str(ref_path)}
    if ref_path is not None and not ref_path.is_file():
        raise AssertionError(f"{name}: no reference image {ref_path}: run pytest "
                             f"--shadelab-regenerate (or {REGENERATE_ENV}=1) to write it")
    ref = as_srgb8(expected, exposure)
    if ref.shape != img.shape:
        raise AssertionError(f"{name}: size {img.shape[1]}x{img.shape[0]} differs from the "
                             f"reference's {ref.shape[1]}x{ref.shape[0]}")
    diff = np.abs(img.astype(np.int16) - ref.astype(np.int16))
    share = float(np.mean(diff.max(axis=2) > limit.pixel))
    rmse = float(np.sqrt(np.mean(diff.astype(np.float64) ** 2)))
    figures = {"share": share, "rmse": rmse, "max_diff": int(diff.max(initial=0))}
    if share > limit.max_share or rmse > limit.max_rmse:
        folder = Path(output_dir or os.environ.get(OUTPUT_ENV) or "shadelab-image-diffs")
        try:
            _save(img, folder / f"{name}_img.png")
            _save(ref, folder / f"{name}_ref.png")
            _save(np.clip(diff * 16, 0, 255).astype(np.uint8), folder / f"{name}_diff.png")
            where = f"see {folder / name}_{{img,ref,diff}}.png"
        except ShadeLabError as exc:
            where = f"no difference images ({exc})"
        label = threshold if isinstance(threshold, str) else "custom"
        hint = _likeliest_term(actual, img)
        raise AssertionError(
            f"{name}: {share:.2%} of pixels differ by > {limit.pixel}/255 (allowed "
            f"{limit.max_share:.2%}), RMSE {rmse:.2f}/255 (allowed {limit.max_rmse}), "
            f"threshold '{label}'; {where}" + (f"\n{hint}" if hint else ""))
    return figures


# ---------------------------------------------------------------- which term is wrong

#: The lecture's terms, each as (what the student may have got wrong, how the reference is
#: re-rendered to show it). A failed comparison of a :func:`render_with_shaders` image renders
#: each variant with ShadeLab's own shaders and names the one the image matches best.
TERM_VARIANTS = (
    ("the ambient term Ia·ka·Od (left out)", "ambient"),
    ("the diffuse term kd·Od·(N·L) (left out)", "diffuse"),
    ("the specular term ks·Os·(R·V)^n (left out)", "specular"),
    ("the attenuation f_att (taken as 1)", "f_att"),
    ("the shadow factor S_i (taken as 1: no shadows)", "shadow"),
    ("the specular model (Phong's (R·V)^n and Blinn's (N·H)^n swapped)", "model"),
)


def _variant(scene, which: str, specular: str):
    """A copy of ``scene`` with one term of the equation changed; the specular model used."""
    from shadelab.scene.preset import clone_scene

    scene = clone_scene(scene)
    if which == "ambient":
        scene.Ia = (0.0, 0.0, 0.0)
    elif which in ("diffuse", "specular"):
        for material in scene.materials.values():
            setattr(material, "kd" if which == "diffuse" else "ks", 0.0)
    elif which == "f_att":
        for light in scene.lights:
            light.attenuation = "none"
    elif which == "shadow":
        scene.render.shadows = "none"
    elif which == "model":
        specular = "blinn" if specular == "phong" else "phong"
    return scene, specular


def likeliest_term(image: Any) -> tuple[str, float, float] | None:
    """For an image from :func:`render_with_shaders`: (the term whose change explains the
    difference best, RMSE of the image to that variant, RMSE to the full equation), both in
    sRGB 8-bit levels, or None when no variant comes within half the full equation's RMSE
    (or the image does not say what it was rendered from)."""
    import numpy as np

    source = getattr(image, "_source", None)
    if source is None:
        return None
    from shadelab.api import render

    scene, size, shading, specular, exact = (*source, False)[:5]
    specular = specular or scene.render.specular
    img = as_srgb8(image).astype(np.float64)

    def rmse(scene_, specular_) -> float:
        ref = as_srgb8(_render_raster(scene_, {}, {}, size, shading, specular_, exact)
                       if exact else render(scene_, size=size, shading=shading,
                                            specular=specular_))
        return float(np.sqrt(np.mean((img - ref) ** 2)))

    full = rmse(scene, specular)
    scores = [(rmse(*_variant(scene, which, specular)), label)
              for label, which in TERM_VARIANTS]
    best, label = min(scores)
    if best >= 0.5 * full:
        return None
    return label, best, full


def _likeliest_term(actual: Any, img) -> str:
    try:
        found = likeliest_term(actual)
    except ShadeLabError:
        return ""
    if found is None:
        return ""
    label, best, full = found
    return (f"likeliest wrong term: {label}: the image is within RMSE {best:.2f}/255 of the "
            f"reference rendered that way, {full:.2f}/255 from the lecture's equation")


# ---------------------------------------------------------------- students' shaders


#: A replaced include starts at line LINE_BASE * (k + 1) + 1 (``#line``), k its index: the
#: compiler's log then tells the student's own line numbers apart from ShadeLab's (drivers do
#: not all report the source-string number of ``#line``, but every one reports the line).
LINE_BASE = 100000


@contextlib.contextmanager
def _includes_replaced(replacements: dict[str, str]):
    """While active, programs compile with these include texts instead of ShadeLab's. Each
    text starts with a ``#line`` after ShadeLab's generated header, so an error in it is
    reported at the line of the student's file (see :func:`_student_lines`)."""
    from shadelab.gl import programs

    original = programs.register_includes

    def register(ctx) -> None:
        original(ctx)
        for index, (key, text) in enumerate(sorted(replacements.items())):
            header = programs.GENERATED_HEADERS.get(key)
            ctx.includes[key] = (header() if header else "") + \
                f"#line {LINE_BASE * (index + 1) + 1}\n" + text

    programs.register_includes = register
    try:
        yield
    finally:
        programs.register_includes = original


def _include_texts(includes: dict[str, str | Path]) -> tuple[dict[str, str], dict[str, str]]:
    """(include name -> GLSL text, include name -> how errors name it: the file or
    ``<include NAME>``)."""
    from collections.abc import Mapping

    from shadelab.resources import shaders_dir

    if not isinstance(includes, Mapping) or not includes:
        raise ShadeLabError(f"includes: expected a mapping of include name to GLSL text or "
                            f"path, got {type(includes).__name__}")
    known = sorted(p.stem for p in (shaders_dir() / "include").glob("*.glsl"))
    texts, names = {}, {}
    for key, source in includes.items():
        if key not in known:
            raise ShadeLabError(f"include '{key}': expected one of {', '.join(known)}")
        if isinstance(source, Path) or (isinstance(source, str) and "\n" not in source
                                        and source.endswith(".glsl")):
            path = Path(source)
            try:
                texts[key] = path.read_text(encoding="utf-8")
            except UnicodeDecodeError:
                raise ShadeLabError(f"{path}: shader is not UTF-8 text") from None
            except OSError as exc:
                raise ShadeLabError(f"{path}: cannot read shader ({exc.strerror})") from None
            names[key] = str(path)
        elif isinstance(source, str):
            texts[key], names[key] = source, f"<include {key}>"
        else:
            raise ShadeLabError(f"include '{key}': expected GLSL text or a .glsl path, got "
                                f"{type(source).__name__}")
    return texts, names


def _student_lines(log: str, texts: dict[str, str], names: dict[str, str]) -> str:
    """The compiler's ``N:LINE(COL)`` references (Mesa's format) rewritten as
    ``file:LINE:COL`` for the lines of a replaced include."""
    import re

    keys = sorted(texts)

    def where(match) -> str:
        index, line = divmod(int(match.group(2)), LINE_BASE)
        if not 1 <= index <= len(keys):
            return match.group(0)
        key = keys[index - 1]
        if line <= texts[key].count("\n") + 1:
            return f"{names[key]}:{line}:{match.group(3)}"
        return f"ShadeLab's shader after {names[key]}"

    return re.sub(r"\b(\d+):(\d+)\((\d+)\)", where, log)


def render_with_shaders(scene: Any, includes: dict[str, str | Path], size: Any = (256, 256),
                        shading: str | None = None, specular: str | None = None, *,
                        exact: bool = True):
    """Render on the raster pipeline with GLSL includes replaced (a student's ``lighting``).

    Parameters
    ----------
    scene : Scene or str
        A scene or a preset name.
    includes : dict
        Include name (a file stem of ``shaders/include``, e.g. ``"lighting"``) to GLSL source
        text or a ``.glsl`` path. The generated ``#define`` header ShadeLab puts before an
        include is kept.
    size, shading, specular
        As :func:`shadelab.render`.
    exact : bool
        Render the lecture's equation exactly as written (default): the shadow-volume pass
        leaves out ShadeLab's terminator fade (a Renderer built with ``exact=True``:
        u_terminator = 0), which a student's chunk does not have. False: ShadeLab's own
        frame, fade included, as :func:`shadelab.render` draws it.

    Returns
    -------
    shadelab.Image
        Linear float32 (H, W, 3), as :func:`shadelab.render` returns it.

    Raises
    ------
    AssertionError
        When the replaced shaders do not compile or link (the GLSL log is in the message).
    """
    from shadelab.api import _scene, _size

    scene = _scene(scene)
    wh = _size(size, "raster")
    texts, names = _include_texts(includes)
    return _render_raster(scene, texts, names, wh, shading, specular, exact)


def reference_image(scene: Any, size: Any = (256, 256), shading: str | None = None,
                    specular: str | None = None, *, exact: bool = True):
    """ShadeLab's own shaders rendered as :func:`render_with_shaders` renders a student's
    (``exact`` by default): the image a course's references are made from."""
    from shadelab.api import _scene, _size

    return _render_raster(_scene(scene), {}, {}, _size(size, "raster"), shading, specular,
                          exact)


def _render_raster(scene, texts: dict[str, str], names: dict[str, str], wh, shading, specular,
                   exact: bool):
    import moderngl

    from shadelab.api import Image
    from shadelab.gl.context import headless_context
    from shadelab.gl.target import RenderTarget
    from shadelab.raster.renderer import Renderer

    ctx = headless_context()
    # its own program cache: the shared renderer stays untouched
    renderer = Renderer(ctx, exact=exact)
    target = RenderTarget(ctx, wh)
    try:
        with _includes_replaced(texts):
            try:
                renderer.render(scene, target, shading, specular)
            except moderngl.Error as exc:
                raise AssertionError("the replaced shaders do not compile: "
                                     f"{_student_lines(str(exc), texts, names)}") from None
        array = target.read()
    finally:
        renderer.release()
        target.release()
    image = Image(array, scene.render.exposure,
                  {"pipeline": "raster", "shading": shading or scene.render.shading,
                   "includes": sorted(texts)})
    image._source = (scene, wh, shading, specular, exact)  # what likeliest_term re-renders
    return image


# ---------------------------------------------------------------- the pytest plugin


class ImageChecker:
    """What the ``shadelab_images`` fixture gives a test (references beside the test file)."""

    def __init__(self, test_dir: Path, regenerate: bool, golden: str = "golden",
                 output: str = "_output", exact: bool = True):
        self.golden_dir = test_dir / golden
        self.output_dir = test_dir / output
        self.regenerate = regenerate
        self.exact = exact  # render() draws the lecture's exact equation (no terminator fade)

    def render(self, scene: Any, includes: dict[str, str | Path] | None = None,
               size: Any = (256, 256), shading: str | None = None,
               specular: str | None = None):
        """:func:`render_with_shaders` (``includes``) or ShadeLab's own shaders (None), with
        this checker's ``exact`` (ini ``shadelab_exact``, default true)."""
        if includes:
            return render_with_shaders(scene, includes, size, shading, specular,
                                       exact=self.exact)
        return reference_image(scene, size, shading, specular, exact=self.exact)

    def check(self, name: str, image: Any, threshold: str | Threshold = "golden",
              exposure: float | None = None) -> dict:
        """Compare ``image`` with ``golden/<name>.png`` (written when regenerating)."""
        return assert_images_close(image, self.golden_dir / f"{name}.png", threshold, name=name,
                                   output_dir=self.output_dir, exposure=exposure,
                                   regenerate=self.regenerate)


def pytest_addoption(parser) -> None:
    group = parser.getgroup("shadelab", "ShadeLab image comparison")
    group.addoption("--shadelab-regenerate", action="store_true", default=False,
                    help="write reference images (golden/<name>.png) instead of comparing")
    parser.addini("shadelab_golden_dir", "folder of reference images, beside each test file",
                  default="golden")
    parser.addini("shadelab_output_dir", "folder for failure images, beside each test file",
                  default="_output")
    parser.addini("shadelab_exact", "shadelab_images.render draws the lecture's exact "
                  "equation (no terminator fade under shadow volumes)", type="bool",
                  default=True)


def _regenerate(config) -> bool:
    return bool(config.getoption("--shadelab-regenerate", default=False)) or \
        regenerate_requested()


try:  # the fixture exists only where pytest does; importing this module never needs it
    import pytest as _pytest
except ImportError:  # pragma: no cover
    _pytest = None

if _pytest is not None:
    @_pytest.fixture
    def shadelab_images(request) -> ImageChecker:
        """Compare images with references beside the test file (``golden/<name>.png``)."""
        return ImageChecker(Path(str(request.node.path)).parent, _regenerate(request.config),
                            request.config.getini("shadelab_golden_dir"),
                            request.config.getini("shadelab_output_dir"),
                            request.config.getini("shadelab_exact"))
