"""The viewer's autosaved session: one file, written atomically, and never a reason not to start.

Pure module (no GL, no GUI). The session is ONE TOML file, ``autosave.toml`` in the state
folder, holding both the scene and where it came from::

    [session]                      # format, source (preset name or file), name, base_dir
    [scene]                        # the scene, exactly as a preset would hold it

It is written to a unique temporary file beside it, fsynced and renamed
(:class:`shadelab.paths.OutputSet`), so two viewers autosaving at once, or a ``kill -9``
during an autosave, leave one whole session of one viewer, never one viewer's scene with
another's metadata.

Reading never fails: a damaged session (truncated, not UTF-8, not a table, nested too deep,
a field out of range, a mesh or image it names that is gone) is moved aside as
``autosave.damaged-<timestamp>.toml`` and :func:`load_session` says so in
:attr:`SessionLoad.note`; the viewer starts with what could be recovered (the scene without
the objects whose files are gone) or with the defaults. A damaged file is never overwritten:
:func:`save_session` moves one aside first.
"""

from __future__ import annotations

import json
import os
import time
from dataclasses import dataclass
from pathlib import Path

import tomli_w

from shadelab.errors import ShadeLabError
from shadelab.paths import OutputSet, file_problem
from shadelab.scene.model import Scene
from shadelab.scene.preset import (
    check_files,
    decode_text,
    parse_toml,
    scene_from_dict,
    scene_to_dict,
)

SESSION_FORMAT = 1
MAX_SESSION_BYTES = 64 * 2**20   # a session holds a scene, not meshes: bigger is damage


def state_dir() -> Path:
    """``$XDG_STATE_HOME/shadelab`` (default ``~/.local/state/shadelab``)."""
    base = os.environ.get("XDG_STATE_HOME") or str(Path.home() / ".local" / "state")
    return Path(base) / "shadelab"


def autosave_path() -> Path:
    return state_dir() / "autosave.toml"


@dataclass
class SessionLoad:
    """What :func:`load_session` found.

    scene, source : the restored scene and its preset name or file; None when none
    note : one line for the status bar when something was wrong ("" when all was well)
    damaged_copy : where the damaged file was moved, or None
    """

    scene: Scene | None = None
    source: str = ""
    note: str = ""
    damaged_copy: Path | None = None

    def __bool__(self) -> bool:
        return self.scene is not None


# ---------------------------------------------------------------- writing


_verified: set[str] = set()   # session files this process has read back (or written)


def save_session(scene: Scene, source: str) -> Path:
    """Write the scene and where it came from as one file, all or nothing."""
    folder = state_dir()
    folder.mkdir(parents=True, exist_ok=True)
    path = autosave_path()
    key = str(path.absolute())
    if key not in _verified and path.exists():
        try:  # not read this run (``--fresh``): a damaged file is kept, not overwritten
            _parse(path)
        except (ShadeLabError, ValueError, RecursionError):
            if move_aside(path) is None:
                raise ShadeLabError(f"{path}: the damaged session could not be moved aside; "
                                    "not overwriting it") from None
    document = {
        "session": {"format": SESSION_FORMAT, "source": source, "name": scene.name,
                    "base_dir": scene.base_dir, "saved_at": time.time(), "pid": os.getpid()},
        "scene": scene_to_dict(scene),
    }
    data = tomli_w.dumps(document).encode("utf-8")
    try:
        with OutputSet() as out:
            out.write("autosave", path, lambda handle: handle.write(data))
    except OSError as exc:
        raise ShadeLabError(f"{path}: cannot write the session ({exc.strerror})") from None
    _verified.add(key)
    legacy = path.with_suffix(".json")  # the older two-file format's metadata
    try:
        legacy.unlink()
    except OSError:
        pass
    return path


def move_aside(path: Path) -> Path | None:
    """Rename a damaged session to ``<stem>.damaged-<timestamp>.toml`` (a new name: nothing
    earlier is replaced); None when it could not be moved."""
    stamp = time.strftime("%Y%m%d-%H%M%S")
    for n in range(1000):
        suffix = f"-{n}" if n else ""
        target = path.with_name(f"{path.stem}.damaged-{stamp}{suffix}{path.suffix}")
        try:
            os.link(path, target)  # fails if the name is taken: never replaces a kept copy
        except FileExistsError:
            continue
        except OSError:
            try:  # a file system without hard links: rename (target checked free above)
                if target.exists():
                    continue
                os.rename(path, target)
                return target
            except OSError:
                return None
        try:
            os.unlink(path)
        except OSError:
            pass
        return target
    return None


# ---------------------------------------------------------------- reading


def _parse(path: Path) -> tuple[dict, dict]:
    """(session table, scene dictionary) of a session file; ShadeLabError when damaged."""
    problem = file_problem(path)
    if problem:
        raise ShadeLabError(f"{path}: {problem}")
    try:
        size = path.stat().st_size
        if size > MAX_SESSION_BYTES:
            raise ShadeLabError(f"{path}: {size / 2**20:.0f} MiB, larger than any session")
        data = path.read_bytes()
    except OSError as exc:
        raise ShadeLabError(f"{path}: cannot read ({exc.strerror})") from None
    raw = parse_toml(decode_text(data, str(path), "session"), str(path))
    if "session" not in raw and "schema_version" in raw:  # the older two-file format
        meta: object = {}
        legacy = path.with_suffix(".json")
        try:
            meta = json.loads(legacy.read_text(encoding="utf-8"))
        except (OSError, ValueError, RecursionError):
            pass
        return (meta if isinstance(meta, dict) else {}), raw
    meta, scene = raw.get("session"), raw.get("scene")
    if not isinstance(meta, dict) or not isinstance(scene, dict):
        raise ShadeLabError(f"{path}: expected a [session] and a [scene] table")
    if meta.get("format") != SESSION_FORMAT:
        raise ShadeLabError(f"{path}: key 'session.format': expected {SESSION_FORMAT}, "
                            f"got {meta.get('format')!r}")
    return meta, scene


def _text(meta: dict, key: str, default: str) -> str:
    value = meta.get(key, default)
    return value if isinstance(value, str) and value else default


def _drop_missing_files(scene: Scene) -> list[str]:
    """Remove objects whose mesh file is gone and image maps that are gone; what was dropped."""
    base = Path(scene.base_dir)

    def gone(value: str) -> bool:
        return file_problem(Path(value) if Path(value).is_absolute() else base / value) \
            is not None

    dropped = []
    kept = []
    for obj in scene.objects:
        if obj.shape == "mesh" and obj.path and gone(obj.path):
            dropped.append(f"mesh '{obj.path}'")
        else:
            kept.append(obj)
    scene.objects = kept
    for name, m in scene.materials.items():
        if m.texture and m.texture != "checker" and gone(m.texture):
            dropped.append(f"texture '{m.texture}' of '{name}'")
            m.texture = ""
        if m.bump and m.bump != "bumps" and gone(m.bump):
            dropped.append(f"bump map '{m.bump}' of '{name}'")
            m.bump = ""
    return dropped


def load_session() -> SessionLoad:
    """The autosaved session; never raises. Falsy when there is none or nothing was usable;
    ``note`` says what was wrong and where the damaged file was kept."""
    path = autosave_path()
    _remove_stale_temporaries(path)
    if not path.exists() and not path.is_symlink():
        return SessionLoad()
    try:
        meta, raw = _parse(path)
        scene = scene_from_dict(raw, str(path))
    except ShadeLabError as exc:
        return _damaged(path, str(exc), None)
    except (RecursionError, MemoryError, ValueError, TypeError) as exc:  # belt and braces
        return _damaged(path, f"{path}: {type(exc).__name__}", None)
    scene.name = _text(meta, "name", "autosave")
    base_dir = _text(meta, "base_dir", str(path.parent))
    scene.base_dir = base_dir
    source = _text(meta, "source", scene.name)
    dropped = _drop_missing_files(scene)
    try:
        check_files(scene, str(path))
    except ShadeLabError as exc:
        return _damaged(path, str(exc), None)
    if dropped:
        more = f" and {len(dropped) - 2} more" if len(dropped) > 2 else ""
        return _damaged(path, f"the autosaved session names files that are gone "
                              f"({', '.join(dropped[:2])}{more}); restored without them",
                        scene, source)
    _verified.add(str(path.absolute()))
    return SessionLoad(scene, source)


STALE_TEMPORARY_S = 600.0   # a temporary this old is a killed writer's, not a live one's


def _remove_stale_temporaries(path: Path) -> None:
    """Temporaries a killed autosave left (``.autosave.toml.*.tmp``, older than 10 min)."""
    now = time.time()
    try:
        leftovers = list(path.parent.glob(f".{path.name}.*.tmp"))
    except OSError:
        return
    for tmp in leftovers:
        try:
            if now - tmp.lstat().st_mtime > STALE_TEMPORARY_S:
                tmp.unlink()
        except OSError:
            pass


def _damaged(path: Path, why: str, scene: Scene | None, source: str = "") -> SessionLoad:
    copy = move_aside(path)
    if copy is not None:
        _verified.add(str(path.absolute()))
    kept = f"kept as '{copy.name}'" if copy else "could not be moved aside"
    if scene is None:
        note = f"the autosaved session was damaged and is {kept}; started from the " \
               f"preset ({why})"
    else:
        note = f"{why}; the session file is {kept}"
    return SessionLoad(scene, source, note.replace("\n", " "), copy)
