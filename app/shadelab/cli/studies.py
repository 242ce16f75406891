"""``shadelab charts`` (speed-vs-accuracy PNG + CSV) and ``shadelab gallery`` (failure cases)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from shadelab.errors import ShadeLabError
from shadelab.studies import STUDIES, run_study


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("charts", help="speed-vs-accuracy charts (PNG + CSV)")
    p.add_argument("--out", default="charts", metavar="DIR", help="folder to write (created)")
    p.add_argument("--quick", action="store_true", help="small images, few repeats (smoke run)")
    p.add_argument("--only", action="append", default=[], metavar="STUDY",
                   help=f"run only these studies ({', '.join(s for s, _ in STUDIES)})")
    p.set_defaults(run=run_charts)

    p = sub.add_parser("gallery", help="render the failure gallery, one PNG per case")
    p.add_argument("--out", default="gallery", metavar="DIR", help="folder to write (created)")
    p.add_argument("--size", default="160x120", metavar="WxH", help="image size per case")
    p.add_argument("--only", action="append", default=[], metavar="CASE",
                   help="render only these cases (names from shadelab.studies.gallery)")
    p.set_defaults(run=run_gallery)


def make_out_dir(text: str) -> Path:
    """Create the output folder (and parents) or fail with one line."""
    path = Path(text)
    if path.exists() and not path.is_dir():
        raise ShadeLabError(f"--out '{text}': exists and is not a folder")
    try:
        path.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise ShadeLabError(f"--out '{text}': cannot create folder ({exc.strerror})") from None
    from shadelab.paths import _is_under, output_problem, shipped_folders

    if any(_is_under(path.resolve(), folder) for folder in shipped_folders()):
        raise ShadeLabError(f"--out '{text}': is a folder shipped with ShadeLab; its files "
                            "would be replaced; choose another folder")
    problem = output_problem(path / "index.md")  # a file can be made there (then removed)
    if problem:
        raise ShadeLabError(f"--out '{text}': {problem}")
    return path


def run_charts(args: argparse.Namespace) -> int:
    known = [s for s, _ in STUDIES]
    for name in args.only:
        if name not in known:
            raise ShadeLabError(f"--only '{name}': expected one of {', '.join(known)}")
    out = make_out_dir(args.out)
    from shadelab.studies.charts import write_chart

    for name in known:
        if args.only and name not in args.only:
            continue
        print(f"charts: {name} ...", file=sys.stderr, flush=True)
        result = run_study(name, bool(args.quick))
        for path in write_chart(result, out):
            print(f"wrote {path}")
        for note in result.notes:
            print(f"  {note}")
    return 0


def run_gallery(args: argparse.Namespace) -> int:
    from shadelab.imageio import parse_size, write_png
    from shadelab.studies.gallery import GALLERY, render_case

    size = parse_size(args.size)
    names = [case.name for case in GALLERY]
    for name in args.only:
        if name not in names:
            raise ShadeLabError(f"--only '{name}': expected one of {', '.join(names)}")
    out = make_out_dir(args.out)
    index = ["# ShadeLab failure gallery", "",
             "Written by `shadelab gallery`; each case is `PRESET` + `--set` overrides, drawn "
             "with its method. Reproduce one in the viewer with `shadelab PRESET --set ...`.", ""]
    for case in GALLERY:
        if args.only and case.name not in args.only:
            continue
        image, exposure = render_case(case, size)
        path = out / f"{case.name}.png"
        write_png(str(path), image, exposure)
        print(f"wrote {path}")
        sets = " ".join(f"--set {o}" for o in case.overrides)
        index += [f"## {case.name}", "", f"![{case.name}]({case.name}.png)", "",
                  f"`{case.preset}` {sets} ({case.method}); test `{case.test_name}`", "",
                  case.explanation, ""]
    if not args.only:
        (out / "index.md").write_text("\n".join(index), encoding="utf-8")
    return 0
