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

    if isinstance(image, (str, Path)):
        from PIL import Image as PILImage

        path = Path(image)
        if not path.is_file():
            raise ShadeLabError(f"{path}: image file not found")
        with PILImage.open(path) as im:
            return np.asarray(im.convert("RGB"))
    if hasattr(image, "array") and hasattr(image, "exposure"):
        return to_srgb8(image.array, image.exposure if exposure is None else exposure)
    a = np.asarray(image)
    if a.ndim != 3 or a.shape[2] not in (3, 4):
        raise ShadeLabError(f"image: expected an (H, W, 3) array, got shape {a.shape}")
    a = a[..., :3]
    if a.dtype == np.uint8:
        return np.ascontiguousarray(a)
    return to_srgb8(a.astype(np.float32), 1.0 if exposure is None else exposure)


def _save(array, path: Path) -> None:
    from PIL import Image as PILImage

    PILImage.fromarray(array).save(path)


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
        ref_path.parent.mkdir(parents=True, exist_ok=True)
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
        folder.mkdir(parents=True, exist_ok=True)
        _save(img, folder / f"{name}_img.png")
        _save(ref, folder / f"{name}_ref.png")
        _save(np.clip(diff * 16, 0, 255).astype(np.uint8), folder / f"{name}_diff.png")
        label = threshold if isinstance(threshold, str) else "custom"
        raise AssertionError(
            f"{name}: {share:.2%} of pixels differ by > {limit.pixel}/255 (allowed "
            f"{limit.max_share:.2%}), RMSE {rmse:.2f}/255 (allowed {limit.max_rmse}), "
            f"threshold '{label}'; see {folder / name}_{{img,ref,diff}}.png")
    return figures


# ---------------------------------------------------------------- students' shaders


@contextlib.contextmanager
def _includes_replaced(replacements: dict[str, str]):
    """While active, programs compile with these include texts instead of ShadeLab's."""
    from shadelab.gl import programs

    original = programs.register_includes

    def register(ctx) -> None:
        original(ctx)
        for key, text in replacements.items():
            header = programs.GENERATED_HEADERS.get(key)
            ctx.includes[key] = (header() if header else "") + text

    programs.register_includes = register
    try:
        yield
    finally:
        programs.register_includes = original


def _include_texts(includes: dict[str, str | Path]) -> dict[str, str]:
    from shadelab.resources import shaders_dir

    known = sorted(p.stem for p in (shaders_dir() / "include").glob("*.glsl"))
    texts = {}
    for key, source in includes.items():
        if key not in known:
            raise ShadeLabError(f"include '{key}': expected one of {', '.join(known)}")
        if isinstance(source, Path) or (isinstance(source, str) and "\n" not in source
                                        and source.endswith(".glsl")):
            path = Path(source)
            try:
                texts[key] = path.read_text(encoding="utf-8")
            except OSError as exc:
                raise ShadeLabError(f"{path}: cannot read shader ({exc.strerror})") from None
        else:
            texts[key] = str(source)
    return texts


def render_with_shaders(scene: Any, includes: dict[str, str | Path], size: Any = (256, 256),
                        shading: str | None = None, specular: str | None = None):
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

    Returns
    -------
    shadelab.Image
        Linear float32 (H, W, 3), as :func:`shadelab.render` returns it.

    Raises
    ------
    AssertionError
        When the replaced shaders do not compile or link (the GLSL log is in the message).
    """
    import moderngl

    from shadelab.api import Image, _scene, _size
    from shadelab.gl.context import headless_context
    from shadelab.gl.target import RenderTarget
    from shadelab.raster.renderer import Renderer

    scene = _scene(scene)
    wh = _size(size, "raster")
    texts = _include_texts(includes)
    ctx = headless_context()
    renderer = Renderer(ctx)  # its own program cache: the shared renderer stays untouched
    target = RenderTarget(ctx, wh)
    try:
        with _includes_replaced(texts):
            try:
                renderer.render(scene, target, shading, specular)
            except moderngl.Error as exc:
                raise AssertionError(f"the replaced shaders do not compile: {exc}") from None
        array = target.read()
    finally:
        renderer.release()
        target.release()
    return Image(array, scene.render.exposure,
                 {"pipeline": "raster", "shading": shading or scene.render.shading,
                  "includes": sorted(texts)})


# ---------------------------------------------------------------- the pytest plugin


class ImageChecker:
    """What the ``shadelab_images`` fixture gives a test (references beside the test file)."""

    def __init__(self, test_dir: Path, regenerate: bool, golden: str = "golden",
                 output: str = "_output"):
        self.golden_dir = test_dir / golden
        self.output_dir = test_dir / output
        self.regenerate = regenerate

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
                            request.config.getini("shadelab_output_dir"))
