"""The ``shadelab`` command line (a stable contract; see README "Command line").

The CLI is the top layer: each subcommand is a module of this package with
``add_parser(subparsers)`` and ``run(args) -> int``; this file only dispatches. Nothing below
imports this package. Bad input raises :class:`ShadeLabError`,
printed here as one line, exit code 2.
"""

from __future__ import annotations

import argparse
import importlib
import os
import signal
import sys
import threading

from shadelab.errors import ShadeLabError
from shadelab.limits import ALLOW_ENV

# Modules that contribute subcommands, in help order.
COMMAND_MODULES = (
    "shadelab.cli.render",
    "shadelab.cli.raytrace",
    "shadelab.cli.radiosity",
    "shadelab.cli.studies",
    "shadelab.cli.bench",
    "shadelab.cli.view",
    "shadelab.cli.warm",
    "shadelab.cli.sweep",
    "shadelab.cli.exercise",
)

# Each subcommand's module: a run imports only the module of the command it names (the viewer's
# start skips the others' imports); help and unknown words get the whole parser.
COMMANDS = {"render": "shadelab.cli.render", "presets": "shadelab.cli.render",
            "validate": "shadelab.cli.render", "raytrace": "shadelab.cli.raytrace",
            "pathtrace": "shadelab.cli.raytrace", "radiosity": "shadelab.cli.radiosity",
            "charts": "shadelab.cli.studies", "gallery": "shadelab.cli.studies",
            "bench": "shadelab.cli.bench", "view": "shadelab.cli.view",
            "warm": "shadelab.cli.warm", "sweep": "shadelab.cli.sweep",
            "exercise": "shadelab.cli.exercise"}

EXIT_BAD_INPUT = 2
EXIT_IO_ERROR = 1      # an output could not be written


class _Parser(argparse.ArgumentParser):
    """argparse that reports usage errors as our one-line error with exit code 2."""

    def error(self, message: str):  # noqa: D102
        raise ShadeLabError(f"{self.prog}: {message}")


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The ``shadelab`` parser: every subcommand, or only ``command``'s module's."""
    parser = _Parser(prog="shadelab",
                     description="ShadeLab: an interactive lab for illumination and shading. "
                                 "Run 'shadelab [PRESET]' to open the viewer (default: lecture).")
    from shadelab import __version__

    parser.add_argument("--version", action="version", version=f"shadelab {__version__}")
    parser.add_argument(*QUIET_FLAGS, action="store_true", help=QUIET_HELP)
    sub = parser.add_subparsers(dest="command", metavar="COMMAND", parser_class=_Parser)
    for name in (COMMAND_MODULES if command not in COMMANDS else (COMMANDS[command],)):
        importlib.import_module(name).add_parser(sub)
    for command in sub.choices.values():  # global: before or after the subcommand
        command.add_argument(*QUIET_FLAGS, action="store_true", default=argparse.SUPPRESS,
                             help=QUIET_HELP)
    return parser


QUIET_FLAGS = ("-q", "--quiet")
QUIET_HELP = "no progress bars and no notes on stderr (errors still print)"


class _Terminated(BaseException):
    """SIGTERM, raised in the main thread so that cleanup runs."""


def _terminated(signum, frame):
    signal.signal(signal.SIGTERM, signal.SIG_DFL)  # a second SIGTERM ends it outright
    raise _Terminated


def _raised_by(exc: BaseException, kind: type) -> bool:
    """True when ``exc`` was caused by an exception of ``kind``: a Ctrl+C that lands inside a
    numba kernel (or its unpickling) surfaces as a chain of SystemErrors around it."""
    seen = set()
    while exc is not None and id(exc) not in seen:
        if isinstance(exc, kind):
            return True
        seen.add(id(exc))
        exc = exc.__cause__ or exc.__context__
    return False


def _interactive(stream) -> bool:
    try:
        return bool(stream.isatty())
    except (AttributeError, ValueError):  # a closed or unusual stream
        return False


def main(argv: list[str] | None = None) -> int:
    argv = list(sys.argv[1:] if argv is None else argv)
    lead = argv[:1] if argv[:1] and argv[0] in QUIET_FLAGS else []  # 'shadelab -q render'
    rest = argv[len(lead):]
    if not rest or (rest[0] not in COMMANDS and rest[0] not in ("-h", "--help", "--version")):
        argv = [*lead, "view", *rest]  # 'shadelab [PRESET] [view options]' opens the viewer
    from shadelab import startup

    if argv[len(lead)] == "view":
        startup.pause_gc()  # until the viewer's first frame (shadelab.startup)
    try:
        parser = build_parser(argv[len(lead)])
    except BaseException:
        startup.resume_gc()
        raise
    saved_allow = os.environ.get(ALLOW_ENV)
    saved_term = None
    from shadelab import progress

    saved_quiet = progress.QUIET
    try:
        args = parser.parse_args(argv)
        # steps over ~2 s (validation, meshes) show a bar on stderr, when a person watches it:
        # a pipe or a log (CI, a script reading the one-line error) gets no carriage returns
        progress.QUIET = bool(getattr(args, "quiet", False))
        progress.SHOW_STEPS = _interactive(sys.stderr) and not progress.QUIET
        from shadelab.paths import NUMBA_CACHE_NOTE

        if NUMBA_CACHE_NOTE:
            progress.note(NUMBA_CACHE_NOTE)
        from shadelab.cli.warm import autowarm

        autowarm(args.command)  # a pip install's first use: kernels compile in the background
        if getattr(args, "allow_large", False):
            os.environ[ALLOW_ENV] = "1"  # seen by every check, and by worker processes
        if args.command != "view" and threading.current_thread() is threading.main_thread():
            # SIGTERM ends a batch job as Ctrl+C does: finally blocks run (worker processes
            # are ended, temporary outputs removed), exit code 128 + 15
            saved_term = signal.signal(signal.SIGTERM, _terminated)
        return int(args.run(args) or 0)
    except ShadeLabError as exc:
        print(f"shadelab: error: {exc}", file=sys.stderr)
        return EXIT_BAD_INPUT
    except MemoryError as exc:  # numpy's _ArrayMemoryError names the size it asked for
        what = str(exc).split(" for an array", 1)[0].strip() or "an allocation failed"
        print(f"shadelab: error: not enough memory ({what}); try a smaller --size, fewer "
              "samples or patches, or a smaller mesh", file=sys.stderr)
        return EXIT_BAD_INPUT
    except KeyboardInterrupt:
        print("shadelab: interrupted", file=sys.stderr)
        return 130
    except _Terminated:
        print("shadelab: terminated", file=sys.stderr)
        return 143
    except SystemError as exc:
        for kind, word, code in ((KeyboardInterrupt, "interrupted", 130),
                                 (_Terminated, "terminated", 143)):
            if _raised_by(exc, kind):
                print(f"shadelab: {word}", file=sys.stderr)
                return code
        raise
    except BrokenPipeError:  # 'shadelab presets | head -1': the reader has what it wanted
        try:
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())  # no flush error
        except (OSError, ValueError):
            pass
        return 0
    except OSError as exc:  # an output that could not be written (disk full, gone, denied)
        name = f" '{exc.filename}'" if exc.filename else ""
        print(f"shadelab: error:{name} {exc.strerror or type(exc).__name__}; nothing more "
              "was written", file=sys.stderr)
        return EXIT_IO_ERROR
    finally:
        startup.resume_gc()  # a view that ended before its first frame (a bad flag, no display)
        progress.QUIET = saved_quiet
        if saved_term is not None:
            signal.signal(signal.SIGTERM, saved_term)
        if saved_allow is None:
            os.environ.pop(ALLOW_ENV, None)
        else:
            os.environ[ALLOW_ENV] = saved_allow


if __name__ == "__main__":
    sys.exit(main())
