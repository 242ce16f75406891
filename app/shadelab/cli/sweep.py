"""``shadelab sweep PRESET KEY=FROM:TO``: one parameter swept over frames, as GIF, MP4 or PNGs.

The lecture's figures in one command each, e.g.::

    shadelab sweep lecture materials.floor.kd=0:1 --frames 11 -o kd.gif
    shadelab sweep lecture lights.0.c2=0:1 --frames 30 -o attenuation.mp4 --grid

Each frame is :func:`shadelab.api.render` of the preset with ``KEY`` set to the frame's value
(validated as ``--set`` is, both ends checked before any work); ``--grid`` puts the three
shading modes side by side. The output is written to a temporary name and renamed at the end,
so Ctrl+C leaves nothing half-written.
"""

from __future__ import annotations

import argparse
import math
import os
import shutil
import tempfile
from pathlib import Path

from shadelab.errors import ShadeLabError

FORMATS = (".gif", ".mp4")
MAX_FRAMES = 10000


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("sweep", help="sweep one preset value over frames: GIF, MP4 or PNGs")
    p.add_argument("preset", metavar="PRESET", help="preset name from presets/ or a path")
    p.add_argument("range", metavar="KEY=FROM:TO", help="e.g. materials.white.kd=0:1")
    p.add_argument("--frames", type=int, default=24, metavar="N", help="frames (default 24)")
    p.add_argument("-o", "--output", required=True, metavar="OUT",
                   help="OUT.gif, OUT.mp4, or a folder (new or empty) for PNG frames")
    p.add_argument("--size", default="320x240", metavar="WxH", help="size of one image")
    p.add_argument("--pipeline", default="raster", help="raster, painter, raytrace, pathtrace "
                                                        "or radiosity")
    p.add_argument("--shading", help="flat | gouraud | phong (raster pipelines)")
    p.add_argument("--grid", action="store_true",
                   help="flat, Gouraud and Phong side by side (raster pipelines)")
    p.add_argument("--fps", type=float, default=12.0, help="frames per second (default 12)")
    p.add_argument("--no-caption", action="store_true", help="leave the value off the frames")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override other preset values")
    p.set_defaults(run=run)


def parse_range(text: str) -> tuple[str, float, float]:
    """``KEY=FROM:TO`` -> (key, from, to)."""
    key, sep, span = text.partition("=")
    lo, sep2, hi = span.partition(":")
    if not sep or not sep2 or not key.strip():
        raise ShadeLabError(f"sweep '{text}': expected KEY=FROM:TO, e.g. materials.white.kd=0:1")
    try:
        a, b = float(lo), float(hi)
    except ValueError:
        raise ShadeLabError(f"sweep '{text}': FROM and TO must be numbers") from None
    if not (math.isfinite(a) and math.isfinite(b)):
        raise ShadeLabError(f"sweep '{text}': FROM and TO must be finite")
    return key.strip(), a, b


def numeric_kind(scene, key: str) -> str:
    """``int`` or ``float``: what the swept field holds (a sweep needs a number)."""
    from shadelab.scene.preset import scene_to_dict

    node = scene_to_dict(scene)
    for part in key.split("."):
        node = node[int(part)] if isinstance(node, list) else node[part]
    if isinstance(node, bool) or not isinstance(node, (int, float)):
        raise ShadeLabError(f"sweep '{key}': expected a numeric key, got {node!r}")
    return "int" if isinstance(node, int) else "float"


def frame_values(a: float, b: float, frames: int, integers: bool) -> list:
    if frames == 1:
        values = [a]
    else:
        values = [a + (b - a) * i / (frames - 1) for i in range(frames)]
    return [int(round(v)) for v in values] if integers else values


def _label(value) -> str:
    return str(value) if isinstance(value, int) else f"{value:.4g}"


def _caption(image, text: str):
    from PIL import ImageDraw, ImageFont

    draw = ImageDraw.Draw(image)
    size = max(10, image.height // 16)
    try:
        font = ImageFont.load_default(size=size)
    except TypeError:  # pillow < 10.1: the fixed bitmap font
        font = ImageFont.load_default()
    box = draw.textbbox((0, 0), text, font=font)
    pad = max(2, size // 4)
    w, h = box[2] - box[0], box[3] - box[1]
    y = image.height - h - 2 * pad
    draw.rectangle((0, y, w + 2 * pad, image.height), fill=(0, 0, 0))
    draw.text((pad - box[0], y + pad - box[1]), text, fill=(255, 255, 255), font=font)
    return image


def _output_kind(path: Path) -> str:
    suffix = path.suffix.lower()
    if suffix in FORMATS:
        if path.is_dir():
            raise ShadeLabError(f"-o '{path}': is a folder, expected a {suffix} file name")
        if not path.resolve().parent.is_dir():
            raise ShadeLabError(f"-o '{path}': folder '{path.resolve().parent}' does not exist")
        return suffix[1:]
    if suffix:
        raise ShadeLabError(f"-o '{path}': expected OUT.gif, OUT.mp4 or a folder for PNGs")
    if path.exists() and (not path.is_dir() or any(path.iterdir())):
        raise ShadeLabError(f"-o '{path}': expected a new or empty folder (nothing in it is "
                            "overwritten)")
    if not path.resolve().parent.is_dir():
        raise ShadeLabError(f"-o '{path}': folder '{path.resolve().parent}' does not exist")
    return "png"


PARTIAL = ".shadelab-partial-"  # in the temporary name of an output being written
STALE_S = 120.0                  # a partial output untouched this long is a dead run's


def _remove_stale_partials(out: Path) -> None:
    """A sweep ended by SIGKILL (no cleanup runs) leaves its temporary output beside the
    target; the next sweep to the same target removes those of its own name untouched for
    STALE_S seconds (a live writer keeps its file fresh)."""
    import shutil
    import time

    folder = out.resolve().parent
    stem = out.name if out.suffix == "" else out.stem
    for leftover in folder.glob(f".{stem}{PARTIAL}*"):
        try:
            if time.time() - leftover.stat().st_mtime < STALE_S:
                continue
            if leftover.is_dir():
                shutil.rmtree(leftover, ignore_errors=True)
            else:
                leftover.unlink()
        except OSError:
            pass


def _check_video(tmp: Path, out: Path, frames: int) -> None:
    """ffmpeg exits 0 after 'Error writing trailer' on a full disk, leaving a truncated file:
    count the frames it wrote before the file replaces ``out``."""
    import errno

    import imageio_ffmpeg

    try:
        written, _ = imageio_ffmpeg.count_frames_and_secs(str(tmp))
    except Exception:  # noqa: BLE001 - an unreadable video is the same failure
        written = 0
    if written != frames:
        raise OSError(errno.EIO, f"the video was not completely written ({written} of "
                                 f"{frames} frames; is the disk full?)", str(out))


def run(args: argparse.Namespace) -> int:
    import numpy as np
    from PIL import Image as PILImage
    from tqdm import tqdm

    from shadelab import api
    from shadelab.imageio import parse_size
    from shadelab.scene.model import SHADING_MODES

    key, a, b = parse_range(args.range)
    if not 1 <= args.frames <= MAX_FRAMES:
        raise ShadeLabError(f"--frames {args.frames}: expected an integer in [1, {MAX_FRAMES}]")
    if not (math.isfinite(args.fps) and 0.1 <= args.fps <= 240):
        raise ShadeLabError(f"--fps {args.fps}: expected a number in [0.1, 240]")
    size = parse_size(args.size)
    if args.pipeline not in api.PIPELINES:
        raise ShadeLabError(f"--pipeline '{args.pipeline}': expected one of "
                            f"{', '.join(api.PIPELINES)}")
    raster = args.pipeline in ("raster", "painter")
    if (args.grid or args.shading) and not raster:
        raise ShadeLabError(f"--grid and --shading apply to the raster and painter pipelines, "
                            f"not {args.pipeline}")
    if args.shading and args.shading not in SHADING_MODES:
        raise ShadeLabError(f"--shading '{args.shading}': expected one of "
                            f"{', '.join(SHADING_MODES)}")
    start = int(a) if a.is_integer() else a
    probe_scene = api.load_preset(args.preset, [*args.set, f"{key}={start}"])  # bad key fails
    integers = numeric_kind(probe_scene, key) == "int"
    if integers and not (a.is_integer() and b.is_integer()):
        raise ShadeLabError(f"sweep '{args.range}': {key} is an integer, expected integer ends")
    values = frame_values(a, b, args.frames, integers)
    for end in (values[0], values[-1]):  # an out-of-range end fails here, before any work
        api.load_preset(args.preset, [*args.set, f"{key}={end}"])
    out = Path(args.output)
    kind = _output_kind(out)
    from shadelab.imageio import check_writable
    from shadelab.scene.preset import scene_inputs

    inputs = scene_inputs(probe_scene, args.preset)
    if kind == "png":  # a new folder (no input is one): can its parent take it?
        from shadelab.paths import output_problem

        problem = output_problem(out.resolve().parent / f".{out.name}-probe")
        if problem:
            raise ShadeLabError(f"-o '{out}': {problem}")
    else:
        check_writable(str(out), "-o", inputs)
    shadings = list(SHADING_MODES) if args.grid else [args.shading]

    def frame(value):
        scene = api.load_preset(args.preset, [*args.set, f"{key}={value}"])
        tiles = []
        for shading in shadings:
            image = api.render(scene, size=size, shading=shading, pipeline=args.pipeline)
            tile = PILImage.fromarray(image.to_srgb8())
            if args.grid:
                tile = _caption(tile, shading)
            tiles.append(np.asarray(tile))
        picture = PILImage.fromarray(np.concatenate(tiles, axis=1))
        if not args.no_caption:
            _caption(picture, f"{key} = {_label(value)}")
        return picture

    _remove_stale_partials(out)
    if kind == "png":
        tmp = Path(tempfile.mkdtemp(prefix=f".{out.name}{PARTIAL}", dir=out.resolve().parent))
    else:
        fd, name = tempfile.mkstemp(prefix=f".{out.stem}{PARTIAL}", suffix=out.suffix,
                                    dir=out.resolve().parent)
        os.close(fd)
        tmp = Path(name)
    writer = None
    gif_frames = []
    try:
        for i, value in enumerate(tqdm(values, desc="sweep", unit="frame")):
            picture = frame(value)
            if kind == "png":
                picture.save(tmp / f"frame_{i:04d}.png")
            elif kind == "gif":
                gif_frames.append(picture)
            else:
                if writer is None:
                    import imageio_ffmpeg

                    w, h = picture.size
                    writer = imageio_ffmpeg.write_frames(
                        str(tmp), (w + w % 2, h + h % 2), fps=args.fps, quality=8,
                        macro_block_size=2, ffmpeg_log_level="error")
                    writer.send(None)
                pixels = np.asarray(picture)
                pixels = np.pad(pixels, ((0, pixels.shape[0] % 2), (0, pixels.shape[1] % 2),
                                         (0, 0)), mode="edge")
                writer.send(np.ascontiguousarray(pixels))
        if kind == "gif":
            gif_frames[0].save(tmp, save_all=True, append_images=gif_frames[1:], loop=0,
                               duration=int(round(1000.0 / args.fps)))
        if writer is not None:
            writer.close()
            writer = None
            _check_video(tmp, out, len(values))
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(tmp, (0o777 if kind == "png" else 0o666) & ~umask)  # mkstemp made it 0600
        if kind == "png" and out.is_dir():
            out.rmdir()  # it was empty (checked above)
        os.replace(tmp, out)
    except BaseException:
        if writer is not None:
            try:
                writer.close()
            except Exception:  # ffmpeg may already be gone (Ctrl+C reaches it too)
                pass
        if tmp.is_dir():
            shutil.rmtree(tmp, ignore_errors=True)
        else:
            tmp.unlink(missing_ok=True)
        raise
    what = "PNG frames" if kind == "png" else kind.upper()
    print(f"wrote {out} ({len(values)} frames, {what}, {key} from {_label(values[0])} to "
          f"{_label(values[-1])})")
    return 0
