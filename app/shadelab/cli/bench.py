"""``shadelab bench``: performance figures as JSON (medians, with the machine).

Each layer contributes a section module with ``run(quick: bool) -> dict`` (timed with
:func:`shadelab.timing.median_time`). Speed is measured here, never asserted by a timed test.
"""

from __future__ import annotations

import argparse
import importlib
import json
import os
import platform
import sys

SECTIONS = (
    ("raster", "shadelab.bench.raster"),
    ("shadows", "shadelab.bench.shadows"),
    ("viewer", "shadelab.bench.viewer"),
    ("raytrace", "shadelab.bench.raytrace"),
    ("radiosity", "shadelab.bench.radiosity"),
)


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("bench", help="performance figures as JSON")
    p.add_argument("--json", metavar="OUT.json", help="write the figures here")
    p.add_argument("--quick", action="store_true", help="fewer frames and samples (smoke run)")
    p.add_argument("--only", action="append", default=[], metavar="SECTION",
                   help=f"run only these sections ({', '.join(s for s, _ in SECTIONS)})")
    p.set_defaults(run=run)


def machine() -> dict:
    """What the figures were measured on."""
    cpu = platform.processor() or platform.machine()
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                if line.startswith("model name"):
                    cpu = line.split(":", 1)[1].strip()
                    break
    except OSError:
        pass
    info = {"cpu": cpu, "cores": os.cpu_count(), "python": sys.version.split()[0],
            "platform": platform.platform(),
            "load_average_1min_at_start": round(os.getloadavg()[0], 2)}
    try:
        from shadelab.gl.context import context_info, headless_context

        gl = context_info(headless_context())
        info["gl_backend"] = gl["backend"]  # egl or native (GLX, WGL, CGL); SHADELAB_GL
        info["gl_renderer"] = gl["renderer"]
        info["gl_version"] = gl["version"]
    except Exception as exc:  # the bench still reports CPU sections without GL
        info["gl_renderer"] = f"unavailable: {exc}"
    return info


def summary(verdict: dict) -> str:
    """One paragraph on stderr: how many goals were met, which failed, which were not
    measured and why."""
    met = sum(row["met"] for row in verdict["checked"])
    lines = [f"bench: goals met {met} of {len(verdict['checked'])} checked"]
    lines += [f"  failed: {row['goal']} ({row['bound']}; measured {row['value']:.3g})"
              for row in verdict["checked"] if not row["met"]]
    lines += [f"  not measured: {row['goal']}: {row['why']}" for row in verdict["unmeasured"]]
    return "\n".join(lines)


def run(args: argparse.Namespace) -> int:
    if args.json:
        from shadelab.imageio import check_writable

        check_writable(args.json, "--json")
    known = {name for name, _ in SECTIONS}
    for name in args.only:
        if name not in known:
            from shadelab.errors import ShadeLabError

            raise ShadeLabError(f"--only '{name}': expected one of {', '.join(sorted(known))}")
    from shadelab.bench import goals

    report = {"machine": machine(), "quick": bool(args.quick), "peers": goals.peers(),
              "sections": {}}
    for name, module_name in SECTIONS:
        if args.only and name not in args.only:
            continue
        module = importlib.import_module(module_name)
        print(f"bench: {name} ...", file=sys.stderr, flush=True)
        report["sections"][name] = module.run(bool(args.quick))
    report["machine"]["load_average_1min_at_end"] = round(os.getloadavg()[0], 2)
    report["meets_goals"] = verdict = goals.check(report["sections"], report["peers"])
    print(summary(verdict), file=sys.stderr, flush=True)
    text = json.dumps(report, indent=2)
    if args.json:
        with open(args.json, "w", encoding="utf-8") as f:
            f.write(text + "\n")
    print(text)
    return 0
