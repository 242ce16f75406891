"""Files the user names: why one cannot be read, and writing outputs all-or-nothing.

Pure standard library, so every layer may use it. Reading: :func:`file_problem` turns what
``stat`` says (missing, a folder, a FIFO, a symlink loop, a name too long) into the few words
of a one-line error. Writing: :class:`OutputSet` writes each output of a run to a unique
temporary file beside its target, fsyncs it and renames them all only once every one was
written, so a failed or interrupted run leaves nothing half-written and no stray file; an
existing target keeps its permission bits, and a symlink target is written through (the file
it points at is replaced, the link stays a link).
"""

from __future__ import annotations

import errno
import os
import stat
import sys
import tempfile
from pathlib import Path
from typing import Callable

from shadelab.errors import ShadeLabError


def _reason(exc: OSError) -> str:
    if exc.errno == errno.ENOENT:
        return "not found"
    if exc.errno == errno.ELOOP:
        return "is a symlink loop"
    if exc.errno == errno.ENAMETOOLONG:
        return "has a name too long for the file system"
    if exc.errno == errno.ENOTDIR:
        return "has a file where a folder is expected"
    return exc.strerror or type(exc).__name__


def file_problem(path: str | Path) -> str | None:
    """None if ``path`` is a readable regular file, else why not ("not found", ...)."""
    if "\n" in str(path) or "\r" in str(path):
        return "has a line break in its name"
    try:
        info = os.stat(path)
    except (OSError, ValueError) as exc:
        return _reason(exc) if isinstance(exc, OSError) else "is not a valid path"
    if stat.S_ISDIR(info.st_mode):
        return "is a folder, expected a file"
    if not stat.S_ISREG(info.st_mode):
        return "is not a regular file (a FIFO, socket or device)"
    if not os.access(path, os.R_OK):
        return "is not readable (permission denied)"
    return None


def output_problem(path: str | Path) -> str | None:
    """None if a file can be written at ``path`` (nothing is created), else why not."""
    text = str(path)
    if not text:
        return "is empty"
    if "\n" in text or "\r" in text or "\x00" in text:
        return "has a line break or NUL in its name"
    target = Path(path)
    if len(os.fsencode(target.name)) > 255:
        return "has a name too long for the file system"
    try:
        info = os.stat(target)  # follows links: a loop or a too-long name says so here
    except FileNotFoundError:
        info = None
        if target.is_symlink():  # dangling: written through to where the link points
            target = resolve_link(target)
    except OSError as exc:
        return _reason(exc)
    if info is not None:
        if stat.S_ISDIR(info.st_mode):
            return "is a folder, expected a file name"
        if not stat.S_ISREG(info.st_mode):
            return "is not a regular file (a FIFO, socket or device)"
        if not info.st_mode & 0o222:  # the user's own "keep this": respected even by root
            return "is read-only (not writable; make it writable or choose another name)"
    folder = target.parent
    try:
        folder_info = os.stat(folder)
    except FileNotFoundError:
        return f"folder '{folder.resolve()}' does not exist"
    except OSError as exc:
        return f"folder '{folder}' {_reason(exc)}"
    if not stat.S_ISDIR(folder_info.st_mode):
        return f"'{folder}' is not a folder"
    try:  # the real test: a temporary file there (what the write will make), removed again
        fd, probe = tempfile.mkstemp(prefix=".shadelab-probe.", dir=folder)
    except OSError as exc:
        return f"not writable (folder '{folder}': {exc.strerror})"
    os.close(fd)
    os.unlink(probe)
    return None


def resolve_link(path: Path) -> Path:
    """Where a (possibly dangling) symlink chain ends; the path itself if it is no link."""
    seen = 0
    while path.is_symlink():
        seen += 1
        if seen > 40:
            raise ShadeLabError(f"'{path}': symlink loop")
        link = Path(os.readlink(path))
        path = link if link.is_absolute() else path.parent / link
    return path


def same_file(a: str | Path, b: str | Path) -> bool:
    try:
        return os.path.samefile(a, b)
    except OSError:
        return False


def _is_under(path: Path, folder: Path) -> bool:
    try:
        path.relative_to(folder)
        return True
    except ValueError:
        return False


def shipped_folders() -> list[Path]:
    """The folders of files shipped with ShadeLab: the package, its presets and shaders."""
    from shadelab.resources import presets_dir, shaders_dir

    folders = [Path(__file__).resolve().parent]
    for find in (presets_dir, shaders_dir):
        try:
            folders.append(find().resolve())
        except FileNotFoundError:
            pass
    return folders


def clobber_problem(path: str | Path, inputs=()) -> str | None:
    """None if writing ``path`` destroys nothing the run reads or ShadeLab ships, else why:
    ``inputs`` are (what, file) pairs (the preset, its meshes, textures, bump maps, a lesson);
    a file shipped with ShadeLab (:func:`shipped_folders`) is never overwritten either."""
    text = str(path)
    if not text:
        return None
    target = Path(path)
    for what, source in inputs:
        if source and (same_file(target, source)
                       or target.absolute() == Path(source).absolute()):
            return f"is the {what} this run reads; writing it would destroy it; choose " \
                "another name"
    try:
        real = resolve_link(target).resolve()
    except (OSError, ShadeLabError, RuntimeError):
        return None
    if real.is_file() and any(_is_under(real, folder) for folder in shipped_folders()):
        return "is a file shipped with ShadeLab; writing it would replace it; choose another name"
    return None


def check_output(path: str | Path | None, flag: str, inputs=()) -> None:
    """The one guard of every writer: ``path`` can be written (:func:`output_problem`) and
    is none of the run's inputs nor a shipped file (:func:`clobber_problem`); one line."""
    if path is None or path == "":
        return
    problem = output_problem(path) or clobber_problem(path, inputs)
    if problem:
        raise ShadeLabError(f"{flag} '{path}': {problem}")


class OutputSet:
    """Outputs of one run, written to temporary files and renamed only all together.

    >>> with OutputSet() as out:                           # doctest: +SKIP
    ...     out.write("-o", "a.png", lambda f: image.save(f, format="PNG"))
    ...     out.write("--npy", "a.npy", lambda f: np.save(f, array))
    On an exception (Ctrl+C included) every temporary file is removed and no target changes.
    """

    def __init__(self) -> None:
        self._staged: list[tuple[str, Path, Path]] = []  # (flag, temporary, final target)

    def __enter__(self) -> OutputSet:
        return self

    def write(self, flag: str, path: str | Path, writer: Callable) -> None:
        """Stage one output: ``writer(binary_file)`` writes its bytes."""
        target = resolve_link(Path(path))
        fd, tmp = tempfile.mkstemp(prefix=f".{target.name[:200]}.", suffix=".tmp",
                                   dir=target.parent)
        tmp_path = Path(tmp)
        self._staged.append((flag, tmp_path, target))
        try:
            with os.fdopen(fd, "wb") as handle:
                writer(handle)
                handle.flush()
                os.fsync(handle.fileno())
        except OSError as exc:
            raise ShadeLabError(f"{flag} '{path}': cannot write ({exc.strerror or exc}); "
                                "nothing was written") from None
        try:  # keep an existing file's permission bits (mkstemp makes 0600)
            mode = stat.S_IMODE(os.stat(target).st_mode)
        except OSError:
            umask = os.umask(0)
            os.umask(umask)
            mode = 0o666 & ~umask
        os.chmod(tmp_path, mode)

    def commit(self) -> None:
        for flag, tmp, target in self._staged:
            try:
                os.replace(tmp, target)
            except OSError as exc:
                raise ShadeLabError(f"{flag} '{target}': cannot write ({exc.strerror})") from None
        self._staged.clear()

    def discard(self) -> None:
        for _flag, tmp, _target in self._staged:
            try:
                tmp.unlink()
            except OSError:
                pass
        self._staged.clear()

    def __exit__(self, exc_type, exc, tb) -> None:
        if exc_type is None:
            try:
                self.commit()
            finally:
                self.discard()
        else:
            self.discard()


# ---------------------------------------------------------------- the numba cache folder

NUMBA_ENV = "NUMBA_CACHE_DIR"
#: One line for the CLI to print when the cache folder could not be used (else None).
NUMBA_CACHE_NOTE: str | None = None


def user_cache_root() -> Path:
    """ShadeLab's cache folder: ``$SHADELAB_CACHE_DIR``, else ``$XDG_CACHE_HOME/shadelab``,
    else ``~/.cache/shadelab`` (the mesh cache's folder, :mod:`shadelab.geometry.cache`)."""
    chosen = os.environ.get("SHADELAB_CACHE_DIR", "").strip()
    if chosen and chosen.lower() != "off":
        return Path(chosen)
    base = os.environ.get("XDG_CACHE_HOME") or str(Path.home() / ".cache")
    return Path(base) / "shadelab"


def folder_problem(folder: Path) -> str | None:
    """None if ``folder`` is, or can be made, a writable folder (nothing is created)."""
    probe = folder
    while True:
        try:
            info = os.stat(probe)
        except FileNotFoundError:
            if probe.parent == probe:
                return "has no existing parent folder"
            probe = probe.parent
            continue
        except OSError as exc:
            return _reason(exc)
        if not stat.S_ISDIR(info.st_mode):
            return f"cannot be made: '{probe}' is not a folder"
        if not os.access(probe, os.W_OK | os.X_OK):
            return f"is not writable ('{probe}': permission denied)"
        return None


def configure_numba_cache() -> str | None:
    """Point numba's on-disk kernel cache at ``<user cache>/numba`` (never site-packages,
    which numba's default would use and which many installs cannot write), unless the user
    set ``NUMBA_CACHE_DIR`` already. Must run before numba is first imported: ``import
    shadelab`` calls it (the one place). A folder that cannot be written falls back to one
    under the system's temporary folder; the reason is kept in :data:`NUMBA_CACHE_NOTE`
    (one line, printed by the CLI) and returned. Nothing is created here."""
    global NUMBA_CACHE_NOTE
    folder = os.environ.get(NUMBA_ENV, "")
    if not folder:
        try:
            wanted = user_cache_root() / "numba"
            problem = folder_problem(wanted)
        except (RuntimeError, KeyError, OSError):  # no home folder (Path.home() fails)
            wanted, problem = Path("~/.cache/shadelab/numba"), "has no home folder to live in"
        folder = str(wanted)
        if problem:
            uid = os.getuid() if hasattr(os, "getuid") else 0
            fallback = Path(tempfile.gettempdir()) / f"shadelab-numba-{uid}"
            if folder_problem(fallback) is None:
                folder = str(fallback)
                NUMBA_CACHE_NOTE = (f"numba cache folder '{wanted}' {problem}; kernels are "
                                    f"cached in '{fallback}' instead")
            else:
                NUMBA_CACHE_NOTE = (f"numba cache folder '{wanted}' {problem}; kernels will "
                                    "compile again in every process")
        os.environ[NUMBA_ENV] = folder
    config = sys.modules.get("numba.core.config")
    if config is not None and not getattr(config, "CACHE_DIR", ""):
        config.CACHE_DIR = folder  # numba imported first (a notebook): its locator reads this
    return NUMBA_CACHE_NOTE
