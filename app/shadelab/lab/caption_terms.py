"""The equation is the caption, and it is live (issue 22): the caption's terms found in its
text, each with its colour (the Equation & probe window uses the same), laid out in wrapped
lines, switched off and on by a click, and read at the probed point.

Pure (no GUI): :func:`segments` splits a caption into plain text and terms; :func:`layout`
places them in lines for a ``measure(text) -> width`` (ImGui's at draw time, a stand-in in
tests); :func:`toggle_term` switches a term in ``state.view.terms_off``; :func:`term_value`
is a term's value at the probe (what the caption shows under the term).
"""

from __future__ import annotations

import re
from dataclasses import dataclass

import numpy as np

from shadelab.shading.codes import TERMS

# One colour per term (RGBA, 0-1), the caption's and the Equation & probe window's
TERM_COLORS = {
    "ambient": (0.45, 0.72, 1.00, 1.0),      # blue
    "diffuse": (0.45, 0.92, 0.45, 1.0),      # green
    "specular": (1.00, 0.58, 0.25, 1.0),     # orange
    "attenuation": (1.00, 0.88, 0.30, 1.0),  # yellow
    "shadow": (0.80, 0.60, 1.00, 1.0),       # violet
}
TERM_LABELS = {"ambient": "ambient Ia ka Od", "diffuse": "diffuse kd Od (N.L_i)",
               "specular": "specular ks Os (R_i.V)^n", "attenuation": "attenuation f_att,i",
               "shadow": "shadow S_i"}
assert tuple(TERM_COLORS) == TERMS and tuple(TERM_LABELS) == TERMS

_DOT = r"\s*\.\s*"
# How each term is written in the lecture's captions (presets/lessons) and the equation line
TERM_PATTERNS = {
    "ambient": r"Ia(?:_lambda)? ka(?: Od(?:_lambda)?)?",
    "diffuse": r"kd(?: Od(?:_lambda)?)? (?:cos\(theta\)|\(\s*N" + _DOT + r"L(?:_i)?\s*\))",
    "specular": r"ks(?: Os(?:_lambda)?)? \(\s*(?:R(?:_i)?" + _DOT + r"V|N" + _DOT
                + r"H(?:_i)?)\s*\)\^n",
    "attenuation": r"\bf_att(?:,i)?",
    "shadow": r"\bS_i\b",
}
_TERM_RE = re.compile("|".join(f"(?P<{name}>{pattern})"
                               for name, pattern in TERM_PATTERNS.items()))


def segments(text: str) -> list[tuple[str, str | None]]:
    """``text`` as (piece, term or None) in order; the pieces join back to ``text``."""
    out: list[tuple[str, str | None]] = []
    at = 0
    for match in _TERM_RE.finditer(text):
        if match.start() > at:
            out.append((text[at:match.start()], None))
        out.append((match.group(0), match.lastgroup))
        at = match.end()
    if at < len(text):
        out.append((text[at:], None))
    return out


def terms_in(text: str) -> list[str]:
    """The terms a caption shows, each once, in the order of :data:`TERMS`."""
    found = {term for _, term in segments(text) if term}
    return [t for t in TERMS if t in found]


@dataclass
class Run:
    """One piece of a laid-out caption: its text, its term (None: plain), its line and x."""

    text: str
    term: str | None
    line: int
    x: float
    width: float


CLAUSE_BREAK = "  "   # two spaces or more part a caption's clauses ("...,   R = 2 N (N . L)")
CLAUSE = "<clause>"   # the mark a clause's start gets among the tokens


def _tokens(text: str) -> list[tuple[str, str | None]]:
    """Wrap units: a term whole, plain text cut after each space; '\\n' alone; the start of a
    clause marked by an empty CLAUSE token (the layout keeps a short clause on one line)."""
    out: list[tuple[str, str | None]] = []
    for piece, term in segments(text):
        if term:
            out.append((piece, term))
            continue
        for part in re.split(r"(\n)", piece):
            if part == "\n":
                out.append(("\n", None))
                continue
            for w in re.findall(r"\S*\s*|\s+", part):
                if w:
                    out.append((w, None))
                    if w.endswith(CLAUSE_BREAK):
                        out.append(("", CLAUSE))
    return out


def _clause_width(tokens, start: int, measure) -> float:
    """Width of the clause that starts at ``tokens[start]`` (to the next clause or line)."""
    total = 0.0
    for token, term in tokens[start:]:
        if token == "\n" or term == CLAUSE:
            break
        total += measure(token)
    return total


def layout(text: str, width: float, measure) -> list[Run]:
    """The caption's runs wrapped to ``width`` (a unit that does not fit starts a new line;
    a unit wider than a line gets one to itself); ``measure(text)`` is its width."""
    runs: list[Run] = []
    line, x = 0, 0.0
    tokens = _tokens(text)
    for k, (token, term) in enumerate(tokens):
        if token == "\n":
            line, x = line + 1, 0.0
            continue
        if term == CLAUSE:      # a clause that fits a line but not this one: a new line
            clause = _clause_width(tokens, k + 1, measure)
            if x > 0.0 and x + clause > width and clause <= width:
                line, x = line + 1, 0.0
            continue
        w = measure(token)
        if x > 0.0 and x + measure(token.rstrip()) > width:
            line, x = line + 1, 0.0
            if not term and not token.strip():
                continue            # a space at a line break is dropped
        if runs and runs[-1].term is None and term is None and runs[-1].line == line:
            runs[-1].text += token  # plain words joined: fewer draw calls
            runs[-1].width += w
        else:
            runs.append(Run(token, term, line, x, w))
        x += w
    return runs


def line_count(runs: list[Run]) -> int:
    return max((r.line for r in runs), default=-1) + 1


def lines_with_terms(runs: list[Run]) -> set[int]:
    """The lines that carry a term: each gets a row for the probed values under it."""
    return {r.line for r in runs if r.term}


# ---------------------------------------------------------------- switching and reading


def terms_switchable(state) -> bool:
    """The viewport shows a raster image, where the switches act (the offline pipelines and a
    shown radiosity solution draw the whole equation: their caption's terms are not buttons)."""
    from shadelab.lab.pipeline_view import RASTER, current

    return current(state) in RASTER and not state.offline.show_radiosity


def toggle_term(state, term: str) -> bool:
    """Switch ``term`` off (or on again) in the viewport's image and the probe; True: now on."""
    if term not in TERMS:
        raise ValueError(f"term '{term}': expected one of {', '.join(TERMS)}")
    off = set(state.view.terms_off)
    off.symmetric_difference_update({term})
    state.view.terms_off = frozenset(off)
    if state.probe.pixel is not None:
        state.probe.requested = True    # the probed values follow the image
    state.status = f"{term} {'off' if term in off else 'on'} (click the term again)"
    return term not in off


def _short(v: float) -> str:
    return f"{v:.2f}" if abs(v) >= 0.005 or v == 0 else f"{v:.0e}"


def _rgb_text(rgb) -> str:
    c = np.asarray(rgb, dtype=np.float64).reshape(-1)[:3]
    if np.ptp(c) <= 5e-3:
        return _short(float(c.mean()))
    return " ".join(_short(float(v)) for v in c)


def term_value(result, term: str) -> np.ndarray | list[float]:
    """The term's value at the probed point: ambient (3,), diffuse and specular (3,) summed
    over the lights, f_att and S_i one number per light."""
    terms = result.terms
    if term == "ambient":
        return np.asarray(terms.ambient, dtype=np.float64)
    if term in ("diffuse", "specular"):
        total = np.zeros(3)
        for light in terms.lights:
            total = total + np.asarray(getattr(light, term), dtype=np.float64)
        return total
    if term == "attenuation":
        return [float(t.f_att) for t in terms.lights]
    if term == "shadow":
        return [float(np.mean(t.shadow)) for t in terms.lights]
    raise ValueError(term)


MAX_LISTED = 3   # per-light values listed under f_att and S_i before "..."


def term_value_text(result, term: str, off: bool = False) -> str:
    """What the caption shows under ``term`` at the probe ("off" when switched off)."""
    if off:
        return "off"
    if result is None:
        return ""
    value = term_value(result, term)
    if isinstance(value, list):
        text = " ".join(_short(v) for v in value[:MAX_LISTED])
        return text + (" ..." if len(value) > MAX_LISTED else "")
    return _rgb_text(value)
