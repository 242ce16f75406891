"""The bench's goals in one table, checked on the whole report, and the peers it compares with.

Each goal names the figure it reads (``section.key.subkey`` in the JSON report), the bound and
where it was set. :func:`check` says which goals were checked, which failed and which could
not be measured and why (a section not run or skipped, a peer not installed or failed, a case
that failed, a figure missing), so a report never claims more than it measured. :func:`peers`
names each peer package with the command that installs it.
"""

from __future__ import annotations

import importlib.util
import operator
from dataclasses import dataclass
from importlib import metadata

INSTALL_PEERS = "pip install 'shadelab[bench]'"


@dataclass(frozen=True)
class Goal:
    name: str
    figure: str        # dotted path in the report's "sections"
    op: str            # "<=" or ">="
    bound: float
    source: str        # the issue that set it
    peer: str = ""     # the peer package the figure needs, if any

    def holds(self, value: float) -> bool:
        return {"<=": operator.le, ">=": operator.ge}[self.op](value, self.bound)

    @property
    def text(self) -> str:
        return f"{self.figure} {self.op} {self.bound:g}"


GOALS = (
    Goal("raster within 1.15x of a bare moderngl draw (cornell)",
         "raster.cornell_phong_over_bare", "<=", 1.15, "issue 25"),
    Goal("raster within 1.15x of a bare draw (sphere-shading)",
         "raster.sphere_shading_phong_over_bare", "<=", 1.15, "issue 25"),
    Goal("raster within 1.15x of a bare draw (80k-triangle mesh)",
         "raster.mesh80k_phong_over_bare", "<=", 1.15, "issue 25"),
    Goal("shadow volumes cost at most 1.6x the unshadowed frame (one light)",
         "shadows.ratio_shadowed_over_unshadowed", "<=", 1.6, "issue 13"),
    *(Goal(f"viewer redraw at least 1.2x Polyscope's ({label})",
           f"viewer.cases.{case}.fps_over_polyscope", ">=", 1.2, "issue 25", peer="polyscope")
      for case, label in (("cornell_1280x720", "cornell, 1280x720"),
                          ("lecture_1280x720", "lecture, 1280x720"),
                          ("cornell_1024x768_presenter", "cornell, 1024x768 presenter"),
                          ("lecture_1024x768_presenter", "lecture, 1024x768 presenter"))),
    Goal("viewer's first frame within 1.0 s of process start", "viewer.first_frame_s", "<=",
         1.0, "issue 25"),
    Goal("path tracer at least 0.7x Mitsuba 3 at equal error",
         "raytrace.pathtrace_vs_mitsuba_equal_error", ">=", 0.7, "issue 19", peer="mitsuba"),
    Goal("radiosity within 1.5 % of the converged reference in 2 s",
         "radiosity.radiosity_error_in_2s", "<=", 0.015, "issue 19"),
)


def peers() -> dict:
    """Each peer: installed or not, its version, and the command that installs it."""
    out = {}
    for name in ("polyscope", "mitsuba"):
        installed = importlib.util.find_spec(name) is not None
        version = None
        if installed:
            try:
                version = metadata.version(name)
            except metadata.PackageNotFoundError:
                version = "unknown"
        out[name] = {"installed": installed, "version": version, "install": INSTALL_PEERS}
    return out


def _figure(sections: dict, path: str):
    value = sections
    for part in path.split("."):
        if not isinstance(value, dict) or part not in value:
            return None
        value = value[part]
    return value


def why_missing(sections: dict, goal: Goal) -> str:
    """Why ``goal``'s figure is not in the report: the section (or a case on the way to the
    figure) says it was skipped or failed, the peer's run failed, or the figure is absent."""
    value = sections
    for part in goal.figure.split(".")[:-1]:
        if not isinstance(value, dict) or part not in value:
            break
        value = value[part]
        for key, word in (("skipped", "skipped"), ("error", "failed")):
            reason = value.get(key) if isinstance(value, dict) else None
            if isinstance(reason, str):
                return f"{part} {word}: {reason}"
        if goal.peer and isinstance(value, dict) and isinstance(value.get(goal.peer), str):
            return f"{goal.peer} {value[goal.peer]}"
    return f"{goal.figure} missing from the report"


def check(sections: dict, installed_peers: dict | None = None) -> dict:
    """``checked`` (goal, bound, value, met), ``failed`` (the names of those not met),
    ``unmeasured`` (goal and why) and ``all_met`` (every goal measured and met)."""
    installed_peers = peers() if installed_peers is None else installed_peers
    checked, failed, unmeasured = [], [], []
    for goal in GOALS:
        section = goal.figure.split(".", 1)[0]
        value = _figure(sections, goal.figure)
        if section not in sections:
            why = f"section '{section}' not run"
        elif goal.peer and not installed_peers.get(goal.peer, {}).get("installed"):
            why = f"{goal.peer} not installed ({INSTALL_PEERS})"
        elif not isinstance(value, (int, float)) or isinstance(value, bool):
            why = why_missing(sections, goal)
        else:
            met = goal.holds(float(value))
            checked.append({"goal": goal.name, "bound": goal.text, "value": float(value),
                            "met": met, "source": goal.source})
            if not met:
                failed.append(goal.name)
            continue
        unmeasured.append({"goal": goal.name, "bound": goal.text, "why": why})
    return {"checked": checked, "failed": failed, "unmeasured": unmeasured,
            "all_met": bool(checked) and not failed and not unmeasured}
