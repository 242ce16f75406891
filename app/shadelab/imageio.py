"""Image output and the CLI arguments every renderer shares (PRESET, -o, --size, --set, --npy).

PNGs say what they are: text chunks (``preset``, ``overrides`` as a JSON list of ``--set``
items, ``pipeline``, ``shading``, ``ShadeLab version``, ``Software``) and an sRGB chunk
(with its gAMA fallback). ``.exr`` files hold the linear float32 RGB radiance ``--npy``
writes (OpenEXR's Python bindings; the same text as string attributes of the header).
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np

from shadelab.errors import ShadeLabError
from shadelab.paths import OutputSet, same_file
from shadelab.shading.conventions import to_srgb8

MAX_SIZE = 16384  # pixels per side


def parse_size(text: str) -> tuple[int, int]:
    """``WxH`` (or a single ``N`` for a square) -> (width, height), each in [1, 16384]."""
    parts = text.lower().split("x")
    try:
        if len(parts) == 1:
            w = h = int(parts[0])
        elif len(parts) == 2:
            w, h = int(parts[0]), int(parts[1])
        else:
            raise ValueError
    except ValueError:
        raise ShadeLabError(f"--size '{text}': expected WxH, e.g. 800x600") from None
    if not (1 <= w <= MAX_SIZE and 1 <= h <= MAX_SIZE):
        raise ShadeLabError(f"--size '{text}': expected each side in [1, {MAX_SIZE}]")
    return w, h


IMAGE_FORMATS = {".png": "PNG", ".jpg": "JPEG", ".jpeg": "JPEG", ".tif": "TIFF",
                 ".tiff": "TIFF", ".bmp": "BMP", ".exr": "EXR"}

#: The pipeline each CLI command runs, as the PNG's ``pipeline`` text says it.
COMMAND_PIPELINES = {"render": "raster", "raytrace": "raytrace", "pathtrace": "pathtrace",
                     "radiosity": "radiosity"}

SRGB_INTENT = b"\x00"                       # perceptual
GAMA_SRGB = (45455).to_bytes(4, "big")     # 1/2.2 x 100000, the sRGB chunk's gAMA fallback


def image_metadata(**fields) -> dict[str, str]:
    """The text an image carries: ``fields`` that are set (lists as JSON), the ShadeLab
    version and ``Software``."""
    from shadelab.version import __version__

    meta = {}
    for key, value in fields.items():
        if value is None or value == "" or (isinstance(value, (list, tuple)) and not value
                                            and key != "overrides"):
            continue
        meta[key] = value if isinstance(value, str) else json.dumps(
            list(value) if isinstance(value, tuple) else value)
    meta["ShadeLab version"] = __version__
    meta["Software"] = f"ShadeLab {__version__}"
    return meta


def cli_metadata(args: argparse.Namespace, **extra) -> dict[str, str]:
    """What a CLI render's image says about itself: preset, --set items, pipeline (+ extra)."""
    command = getattr(args, "command", None)
    pipeline = COMMAND_PIPELINES.get(command, command)
    if pipeline == "raster" and getattr(args, "visibility", None) == "painter":
        pipeline = "painter"
    return image_metadata(preset=getattr(args, "preset", None),
                          overrides=list(getattr(args, "set", None) or []),
                          pipeline=pipeline, **extra)


def check_writable(path: str | None, flag: str, inputs=()) -> None:
    """Fail before any work if ``path`` cannot be written, or would overwrite one of
    ``inputs`` or a file shipped with ShadeLab; nothing is created or changed."""
    from shadelab.paths import check_output

    check_output(path or None, flag, inputs)


def check_image_name(path: str | None, flag: str) -> None:
    """An 8-bit image file name: its extension says the format (checked before any work)."""
    if path and Path(path).suffix.lower() not in IMAGE_FORMATS:
        raise ShadeLabError(f"{flag} '{path}': expected an image file name ending in "
                            f"{', '.join(IMAGE_FORMATS)} (--npy writes float data)")
    if path and Path(path).suffix.lower() == ".exr":
        _openexr(flag, path)


def _openexr(flag: str, path: str):
    try:
        import OpenEXR
    except ImportError:
        raise ShadeLabError(f"{flag} '{path}': writing .exr needs OpenEXR's Python bindings "
                            "(pip install OpenEXR)") from None
    return OpenEXR


def _png_writer(path: str, linear: np.ndarray, exposure: float,
                meta: dict[str, str] | None = None):
    if Path(path).suffix.lower() == ".exr":
        return _exr_writer(path, linear, meta)
    from PIL import Image  # here: pillow's import is ~20 ms of the viewer's start

    image = Image.fromarray(to_srgb8(linear, exposure))
    fmt = IMAGE_FORMATS.get(Path(path).suffix.lower(), "PNG")
    if fmt != "PNG":
        return lambda handle: image.save(handle, format=fmt)
    from PIL.PngImagePlugin import PngInfo

    info = PngInfo()
    info.add(b"sRGB", SRGB_INTENT)
    info.add(b"gAMA", GAMA_SRGB)
    for key, value in (meta or image_metadata()).items():
        info.add_text(key, value)  # iTXt where the text is not Latin-1
    return lambda handle: image.save(handle, format="PNG", pnginfo=info)


def _exr_writer(path: str, linear: np.ndarray, meta: dict[str, str] | None = None):
    """Linear float32 RGB (H, W, 3), row 0 at the top, ZIP-compressed, no exposure applied."""
    exr = _openexr("-o", path)
    pixels = np.ascontiguousarray(linear, dtype=np.float32)
    header = {"compression": exr.ZIP_COMPRESSION, "type": exr.scanlineimage}
    header.update(meta or image_metadata())

    def write(handle) -> None:
        try:
            with exr.File(header, {"RGB": pixels}) as image:
                image.write(handle)
        except OSError:
            raise
        except Exception as exc:  # the bindings raise RuntimeError / ValueError
            raise OSError(0, f"OpenEXR: {exc}") from None

    return write


def _npy_writer(linear: np.ndarray):
    array = np.ascontiguousarray(linear, dtype=np.float32)
    return lambda handle: np.save(handle, array)  # a handle: exactly the name given


def write_png(path: str, linear: np.ndarray, exposure: float = 1.0,
              meta: dict[str, str] | None = None) -> None:
    """Write linear RGB (H, W, 3) as an sRGB image (PNG unless the extension says otherwise;
    ``.exr``: linear float32), through a temporary file renamed when complete. ``meta``: the
    PNG's text chunks (default: the version and ``Software`` only)."""
    with OutputSet() as out:
        out.write("-o", path, _png_writer(path, linear, exposure, meta))


def write_npy(path: str, linear: np.ndarray) -> None:
    """Write float32 linear radiance (H, W, 3), row 0 at the top, to exactly ``path``."""
    with OutputSet() as out:
        out.write("--npy", path, _npy_writer(linear))


def add_scene_arguments(parser: argparse.ArgumentParser, default_size: str = "800x600") -> None:
    parser.add_argument("preset", metavar="PRESET", help="preset name from presets/ or a path")
    parser.add_argument("-o", "--output", required=True, metavar="OUT.png",
                        help="image to write: .png (sRGB, with its parameters as text) or "
                             ".exr (linear float RGB)")
    parser.add_argument("--size", default=default_size, metavar="WxH", help="image size")
    parser.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                        help="override a preset value, e.g. materials.white.kd=0.5")
    parser.add_argument("--npy", metavar="OUT.npy", help="also write float32 linear radiance")
    add_allow_large(parser)


def add_allow_large(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--allow-large", action="store_true",
                        help="run work past the size and time limits (images over 16 Mpixels, "
                             "over 268 M samples, 4 M triangles, 10,000 objects, 20,000 "
                             "patches); memory beyond this machine's is refused even then")


def save_outputs(args: argparse.Namespace, image: np.ndarray, exposure: float = 1.0,
                 meta: dict | None = None) -> None:
    """Write -o and --npy together: both are renamed into place only once both are written.
    The image's text: :func:`cli_metadata` of ``args`` and ``meta`` (e.g. the shading)."""
    text = cli_metadata(args, **(meta or {}))
    with OutputSet() as out:
        out.write("-o", args.output, _png_writer(args.output, image, exposure, text))
        if args.npy:
            out.write("--npy", args.npy, _npy_writer(image))


def check_outputs(args: argparse.Namespace, scene=None) -> None:
    """-o and --npy can be written, differ from each other and from every input: the preset,
    the ``scene``'s meshes, textures and bump maps, and the files shipped with ShadeLab."""
    from shadelab.paths import check_output

    inputs = []
    preset = getattr(args, "preset", None)
    if preset or scene is not None:
        from shadelab.scene.preset import resolve_preset, scene_inputs

        if scene is not None:
            inputs = scene_inputs(scene, preset)
        else:
            inputs = [("input preset", resolve_preset(preset))]
    check_output(args.output, "-o", inputs)
    check_image_name(args.output, "-o")
    check_output(args.npy, "--npy", inputs)
    if args.npy and (same_file(args.output, args.npy) or
                     Path(args.output).absolute() == Path(args.npy).absolute()):
        raise ShadeLabError(f"--npy '{args.npy}': the same file as -o; choose another name")
