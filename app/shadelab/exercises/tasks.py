"""The four task kinds: predict a number, which picture, match the target, find the pixel.

Each task computes what it grades against from the lab itself (the probe of
:mod:`shadelab.lab.probe`, raster renders, the attenuation function, the radiosity form
factors and solver, the Whitted ray tree) when :meth:`Task.expected` is first asked, and
caches it. Images come from a renderer, a callable ``render(shot) -> (H, W, 3) float32
linear``: headless it is :func:`shadelab.exercises.headless.api_render` (``shadelab.render``);
the viewer passes the images its GL side drew into :attr:`Task.images` and catches
:class:`NeedImages` meanwhile. No GL or GUI module is imported here.
"""

from __future__ import annotations

import hashlib
import math
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np

from shadelab.errors import ShadeLabError
from shadelab.exercises import regions
from shadelab.exercises.files import (
    Where,
    check_pixel,
    get_int,
    get_number,
    get_numbers,
    get_pixel,
    get_str,
    get_strings,
    is_number,
    load_scene,
    parse_common,
)

CHANNELS = {"r": 0, "g": 1, "b": 2}
LETTERS = "ABCD"


@dataclass(frozen=True)
class Shot:
    """One raster image a task needs: a preset with overrides, size, shading and specular."""

    preset: str
    set: tuple[str, ...]
    size: tuple[int, int]
    shading: str | None = None
    specular: str | None = None

    @property
    def key(self) -> str:
        return hashlib.sha1(repr(self).encode()).hexdigest()[:16]

    def scene(self):
        return load_scene_items(self.preset, list(self.set))


def load_scene_items(preset: str, items: list[str]):
    from shadelab.scene.preset import load_preset

    return load_preset(preset, items)


Renderer = Callable[[Shot], np.ndarray]


class NeedImages(Exception):
    """Raised when a task needs images that no renderer can draw now (the viewer then asks
    its GL side for ``shots`` and tries again next frame)."""

    def __init__(self, shots: dict[str, Shot]):
        super().__init__(f"{len(shots)} image(s) to render")
        self.shots = shots


@dataclass
class Expected:
    """What the lab says: the value graded against, its tolerance, and what shows why."""

    value: Any
    tolerance: float | None
    detail: dict = field(default_factory=dict)


@dataclass
class Result:
    id: str
    kind: str
    value: Any
    answer: Any
    tolerance: float | None
    verdict: str          # "pass" | "fail" | "unanswered"
    message: str = ""
    detail: dict = field(default_factory=dict)

    @property
    def passed(self) -> bool:
        return self.verdict == "pass"

    def to_json(self) -> dict:
        return {"id": self.id, "kind": self.kind, "value": _plain(self.value),
                "answer": _plain(self.answer), "tolerance": self.tolerance,
                "verdict": self.verdict, "message": self.message,
                "detail": _plain(self.detail)}


def _plain(value: Any) -> Any:
    if isinstance(value, dict):
        return {str(k): _plain(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [_plain(v) for v in value]
    if isinstance(value, np.ndarray):
        return _plain(value.tolist())
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, float) and not math.isfinite(value):
        return None
    return value


@dataclass
class Reveal:
    """After the answer: lines of text (the lab's terms, the error) and named images
    (linear RGB) that show why."""

    lines: list[str]
    images: dict[str, np.ndarray] = field(default_factory=dict)


def within(answer: float, value: float, tolerance: float) -> bool:
    """|answer - value| <= tolerance (a hair of float slack at the boundary)."""
    return abs(answer - value) <= tolerance * (1.0 + 1e-9) + 1e-15


def _fmt(value: Any) -> str:
    if isinstance(value, float):
        return f"{value:.4g}"
    if isinstance(value, (list, tuple)):
        return "[" + ", ".join(_fmt(v) for v in value) + "]"
    return str(value)


# ---------------------------------------------------------------- the base


class Task:
    KIND = ""
    KEYS: set[str] = set()

    def __init__(self, where: Where, raw: dict, base: Path):
        self.where = where
        self.id = get_str(raw, "id", where)
        self.title = get_str(raw, "title", where, default=self.id) or self.id
        self.question = get_str(raw, "question", where)
        self.hint = get_str(raw, "hint", where, default="")
        self.reveal_text = get_str(raw, "reveal", where, default="")
        self.common = parse_common(raw, where, base)
        self.images: dict[str, np.ndarray] = {}
        self.render: Renderer | None = None
        self._expected: Expected | None = None
        self.parse(raw, where)

    # ---- for subclasses
    def parse(self, raw: dict, where: Where) -> None:
        pass

    def compute(self) -> Expected:
        raise NotImplementedError

    def parse_answer(self, value: Any, where: Where) -> Any:
        raise NotImplementedError

    def judge(self, answer: Any, expected: Expected) -> tuple[bool, str, dict]:
        raise NotImplementedError

    def reveal_lines(self, expected: Expected, result: Result | None) -> list[str]:
        return []

    def reveal_images(self, expected: Expected, result: Result | None) -> dict:
        return {}

    # ---- shared
    @property
    def size(self) -> tuple[int, int]:
        return self.common.size

    def check(self) -> None:
        """Every scene this task uses loads (the preset and its overrides)."""
        self.scene()
        for shot in self.shots().values():
            self.wrap(shot.scene)

    def wrap(self, call: Callable, *args, **kwargs):
        """Run ``call``; a ShadeLabError gains the task's name."""
        try:
            return call(*args, **kwargs)
        except ShadeLabError as exc:
            raise self.where.bad(str(exc)) from None

    def scene(self, extra: list[str] | None = None):
        return self.wrap(load_scene, self.common, extra)

    def shot(self, extra: tuple[str, ...] = (), shading: str | None = None,
             specular: str | None = None) -> Shot:
        return Shot(self.common.preset, (*self.common.set, *extra), self.size,
                    shading or self.common.shading, specular or self.common.specular)

    def shots(self) -> dict[str, Shot]:
        """The images :meth:`expected` needs, by key."""
        return {}

    def image(self, shot: Shot) -> np.ndarray:
        self.need({shot.key: shot})
        return self.images[shot.key]

    def need(self, shots: dict[str, Shot]) -> None:
        missing = {k: s for k, s in shots.items() if k not in self.images}
        if not missing:
            return
        if self.render is None:
            raise NeedImages(missing)
        for key, shot in missing.items():
            self.images[key] = np.asarray(self.wrap(self.render, shot), np.float32)

    def expected(self) -> Expected:
        """The lab's value (computed once, then cached)."""
        if self._expected is None:
            self.need(self.shots())
            self._expected = self.compute()
        return self._expected

    def grade(self, answer: Any) -> Result:
        """Grade a parsed answer (None: unanswered)."""
        expected = self.expected()
        if answer is None:
            return Result(self.id, self.KIND, expected.value, None, expected.tolerance,
                          "unanswered", "no answer", {})
        ok, message, detail = self.judge(answer, expected)
        return Result(self.id, self.KIND, expected.value, answer, expected.tolerance,
                      "pass" if ok else "fail", message, detail)

    def reveal(self, result: Result | None = None) -> Reveal:
        """Why: the lab's terms, the image difference, the task's own text."""
        expected = self.expected()
        lines = self.reveal_lines(expected, result)
        if self.reveal_text:
            lines.append(self.reveal_text)
        return Reveal(lines, self.reveal_images(expected, result))

    def answer_text(self, answer: Any) -> str:
        return _fmt(answer)

    def bad_answer(self, where: Where, what: str, value: Any) -> ShadeLabError:
        return where.bad(f"expected {what}, got {value!r}"[:300])


# ---------------------------------------------------------------- predict a number

PROBE_QUANTITIES = ("N.L", "R.V", "N.H", "f_att", "S", "spot", "diffuse", "specular",
                    "ambient", "I")
QUANTITIES = (*PROBE_QUANTITIES, "f_att(d)", "F", "B", "rays")
PER_CHANNEL = ("S", "diffuse", "specular", "ambient", "I", "B")
RAY_KINDS = ("all", "primary", "shadow", "reflected", "refracted")


class NumberTask(Task):
    """Predict a number: a term at a probe pixel, f_att at a distance, a form factor, a
    radiosity after k shots of progressive refinement, or the rays of a pixel's ray tree."""

    KIND = "number"
    KEYS = {"quantity", "pixel", "light", "channel", "distance", "patches", "rho", "emission",
            "source", "target", "shots", "patch", "depth", "rays", "tolerance"}

    def parse(self, raw: dict, where: Where) -> None:
        self.quantity = get_str(raw, "quantity", where, choices=QUANTITIES)
        self.tolerance = get_number(raw, "tolerance", where, lo=0.0)
        q = self.quantity
        self.pixel = get_pixel(raw, "pixel", where, self.size) \
            if q in PROBE_QUANTITIES or q == "rays" else None
        self.light = get_int(raw, "light", where, default=0, hi=15)
        self.channel = CHANNELS[get_str(raw, "channel", where, default="r",
                                        choices=tuple(CHANNELS))]
        self.distance = get_number(raw, "distance", where, lo=0.0) if q == "f_att(d)" else None
        self.depth = get_int(raw, "depth", where, default=1, hi=8) if q == "rays" else 0
        self.ray_kind = get_str(raw, "rays", where, default="all", choices=RAY_KINDS)
        self.patches = None
        if q in ("F", "B"):
            polys = raw.get("patches")
            try:
                arr = np.asarray(polys, float)
                ok = arr.ndim == 3 and arr.shape[1] in (3, 4) and arr.shape[2] == 3 \
                    and len(arr) >= 2 and np.all(np.isfinite(arr))
            except (TypeError, ValueError):
                ok = False
            if not ok:
                raise where.fail("patches", "expected a list of at least two polygons, each "
                                            "3 or 4 [x, y, z] corners")
            self.patches = arr
            n = len(arr)
            self.source = get_int(raw, "source", where, default=0, hi=n - 1)
            self.target = get_int(raw, "target", where, default=1, hi=n - 1)
            self.rho = get_numbers(raw, "rho", where, length=n, required=False) or [0.5] * n
            self.emission = get_numbers(raw, "emission", where, length=n, required=False) \
                or [1.0] + [0.0] * (n - 1)
            if any(not 0 <= r < 1 for r in self.rho):
                raise where.fail("rho", "expected reflectances in [0, 1)")
            self.shots_count = get_int(raw, "shots", where, default=1, lo=1, hi=1000)
            self.patch = get_int(raw, "patch", where, default=1, hi=n - 1)

    def probe_data(self) -> dict:
        specular = {"R.V": "phong", "N.H": "blinn"}.get(self.quantity, self.common.specular)
        scene = self.scene()
        data = self.wrap(probe, scene, self.pixel, self.size, self.common.shading, specular)
        if data is None:
            raise self.where.fail("pixel", f"{list(self.pixel)} shows the background")
        if self.quantity not in ("ambient", "I") and self.light >= len(data["lights"]):
            raise self.where.fail("light", f"{self.light}: the scene has "
                                           f"{len(data['lights'])} enabled light(s)")
        return data

    def compute(self) -> Expected:
        q = self.quantity
        if q in PROBE_QUANTITIES:
            data = self.probe_data()
            value = probe_value(data, q, self.light, self.channel)
            return Expected(value, self.tolerance, {"probe": data})
        if q == "f_att(d)":
            from shadelab.shading.reference import attenuation, attenuation_clamped

            lights = self.scene().active_lights()
            if self.light >= len(lights):
                raise self.where.fail("light", f"{self.light}: the scene has {len(lights)} "
                                               "enabled light(s)")
            light = lights[self.light]
            f = float(attenuation(np.array([self.distance]), light.attenuation, light.c1,
                                  light.c2, light.c3)[0])
            clamped = bool(attenuation_clamped(np.array([self.distance]), light)[0])
            return Expected(f, self.tolerance, {"mode": light.attenuation, "c1": light.c1,
                                                "c2": light.c2, "c3": light.c3,
                                                "distance": self.distance, "clamped": clamped})
        if q == "F":
            F = form_factors(self.patches)
            return Expected(float(F[self.source, self.target]), self.tolerance,
                            {"row_sum": float(F[self.source].sum()),
                             "reverse": float(F[self.target, self.source])})
        if q == "B":
            B, shooters = progressive(self.patches, self.rho, self.emission, self.shots_count)
            return Expected(float(B[self.patch, self.channel]), self.tolerance,
                            {"shooters": shooters, "B": B[:, self.channel].tolist()})
        # rays
        from shadelab.raytrace.tree import trace_pixel_tree

        tree = self.wrap(trace_pixel_tree, self.scene(), self.size, self.pixel[0],
                         self.pixel[1], self.depth)
        counts = {k: 0 for k in RAY_KINDS}
        for _, node in tree.flatten():
            counts[node.kind] += 1
            counts["all"] += 1
        return Expected(counts[self.ray_kind], self.tolerance, {"counts": counts})

    def parse_answer(self, value: Any, where: Where) -> float:
        if not is_number(value):
            raise self.bad_answer(where, "a finite number", value)
        return float(value)

    def judge(self, answer: float, expected: Expected):
        ok = within(answer, float(expected.value), self.tolerance)
        err = abs(answer - float(expected.value))
        return ok, f"lab {_fmt(float(expected.value))} +/- {_fmt(self.tolerance)}, " \
                   f"off by {_fmt(err)}", {"error": err}

    def reveal_lines(self, expected: Expected, result: Result | None) -> list[str]:
        lines = [f"{self.quantity} = {_fmt(float(expected.value))} "
                 f"(tolerance +/- {_fmt(self.tolerance)})"]
        d = expected.detail
        if "probe" in d:
            lines += probe_lines(d["probe"])
        elif self.quantity == "f_att(d)":
            lines.append(f"f_att({_fmt(d['distance'])}) with {d['mode']} c1={_fmt(d['c1'])} "
                         f"c2={_fmt(d['c2'])} c3={_fmt(d['c3'])}: min(., 1) clamp "
                         f"{'ACTIVE' if d['clamped'] else 'off'}")
        elif self.quantity == "F":
            lines.append(f"row sum F_{self.source}. = {_fmt(d['row_sum'])}; reverse "
                         f"F_{self.target}{self.source} = {_fmt(d['reverse'])} "
                         "(A_i F_ij = A_j F_ji)")
        elif self.quantity == "B":
            lines.append(f"shooters in order: {d['shooters']}; B after "
                         f"{self.shots_count} shot(s): {_fmt(d['B'])}")
        else:
            lines.append("rays by kind: " + ", ".join(f"{k} {v}" for k, v in
                                                       d["counts"].items() if k != "all"))
        return lines


def probe(scene, pixel: tuple[int, int], size: tuple[int, int], shading: str | None,
          specular: str | None) -> dict | None:
    """The lab's probe (``shadelab.lab.probe``, pure numpy) as the plain data
    ``shadelab.probe`` returns (the fields the exercises use)."""
    from shadelab.lab.probe import probe as run_probe

    result = run_probe(scene, size, pixel, shading, specular)
    if result is None:
        return None

    def vec(v) -> list[float]:
        return [float(c) for c in np.asarray(v, np.float64).reshape(-1)]

    lights = []
    for i, term in enumerate(result.terms.lights):
        shadow = np.asarray(term.shadow, np.float64).reshape(-1)
        lights.append({"to_light": vec(term.to_light), "reflected": vec(result.reflected(i)),
                       "distance": float(term.distance), "f_att": float(term.f_att),
                       "clamped": bool(term.clamp_active), "spot": float(term.spot),
                       "shadow": float(shadow[0]) if np.ptp(shadow) == 0.0 else vec(shadow),
                       "diffuse": vec(term.diffuse), "specular": vec(term.specular)})
    return {"pixel": tuple(pixel), "shading": result.shading, "specular": result.specular,
            "material": result.hit.mesh.material, "normal": vec(result.normal),
            "to_eye": vec(result.to_eye), "ambient": vec(result.terms.ambient),
            "lights": lights, "reference": vec(result.reference)}


def probe_value(data: dict, quantity: str, light: int, channel: int) -> float:
    if quantity in ("ambient", "I"):
        return float(data["ambient" if quantity == "ambient" else "reference"][channel])
    term = data["lights"][light]
    n = np.asarray(data["normal"])
    if quantity == "N.L":
        return max(float(n @ np.asarray(term["to_light"])), 0.0)
    if quantity == "R.V":
        return max(float(np.asarray(term["reflected"]) @ np.asarray(data["to_eye"])), 0.0)
    if quantity == "N.H":
        return max(float(n @ np.asarray(term["reflected"])), 0.0)
    if quantity == "S":
        s = term["shadow"]
        return float(s[channel] if isinstance(s, list) else s)
    if quantity in ("f_att", "spot"):
        return float(term[quantity])
    return float(term[quantity][channel])  # diffuse, specular


def probe_lines(data: dict) -> list[str]:
    n = np.asarray(data["normal"])
    lines = [f"probe at {list(data['pixel'])}: material '{data['material']}', "
             f"{data['shading']} shading, {data['specular']} specular",
             f"ambient Ia ka Od = {_fmt(list(data['ambient']))}"]
    for i, term in enumerate(data["lights"]):
        nl = max(float(n @ np.asarray(term["to_light"])), 0.0)
        other = float(np.asarray(term["reflected"]) @ (
            np.asarray(data["to_eye"]) if data["specular"] == "phong" else n))
        word = "R.V" if data["specular"] == "phong" else "N.H"
        lines.append(f"light {i}: d = {_fmt(term['distance'])}, f_att = {_fmt(term['f_att'])}"
                     f"{' (clamped)' if term['clamped'] else ''}, S = {_fmt(term['shadow'])}, "
                     f"N.L = {_fmt(nl)}, {word} = {_fmt(max(other, 0.0))}")
        lines.append(f"   diffuse = {_fmt(list(term['diffuse']))}, "
                     f"specular = {_fmt(list(term['specular']))}")
    lines.append(f"I = {_fmt(list(data['reference']))}")
    return lines


def form_factors(polygons: np.ndarray) -> np.ndarray:
    """The lab's analytic form factors of a small patch set (exact kernel, quadrature)."""
    from shadelab.radiosity.formfactors import FormFactors
    from shadelab.radiosity.patches import from_polygons

    return FormFactors(from_polygons(polygons), "analytic").matrix()


def progressive(polygons: np.ndarray, rho: list[float], emission: list[float],
                shots: int) -> tuple[np.ndarray, list[int]]:
    """B after ``shots`` shots of the lab's progressive refinement, and who shot."""
    from shadelab.radiosity.formfactors import FormFactors
    from shadelab.radiosity.patches import from_polygons
    from shadelab.radiosity.solvers import solve_progressive

    patches = from_polygons(polygons, rho=np.asarray(rho), emission=np.asarray(emission))
    ff = FormFactors(patches, "analytic")
    shooters: list[int] = []

    def row(i: int) -> np.ndarray:
        shooters.append(int(i))
        return ff.row(i)

    B = patches.E.copy() if hasattr(patches, "E") else None
    for step in solve_progressive(row, patches.areas, patches.rho, patches.E, max_shots=shots,
                                  tolerance=0.0):
        B = step.B.copy()
    return np.asarray(B), shooters


# ---------------------------------------------------------------- which picture


@dataclass
class Option:
    label: str
    set: list[str]
    shading: str | None
    specular: str | None


class ChoiceTask(Task):
    """Which picture: two to four images of one scene under one camera; which one is X?
    The options are shown in an order drawn from the task's id (not the file's order)."""

    KIND = "choice"
    KEYS = {"options", "correct"}

    def parse(self, raw: dict, where: Where) -> None:
        items = raw.get("options")
        if not isinstance(items, list) or not 2 <= len(items) <= 4:
            raise where.fail("options", "expected 2 to 4 [[tasks.options]] tables")
        self.options = []
        for i, item in enumerate(items):
            w = Where(where.source, f"{where.task}: options[{i}]")
            if not isinstance(item, dict):
                raise where.fail(f"options[{i}]", "expected a table")
            unknown = sorted(set(item) - {"label", "set", "shading", "specular"})
            if unknown:
                raise w.fail(unknown[0], "unknown key (expected label, set, shading, "
                                         "specular)")
            self.options.append(Option(
                get_str(item, "label", w), get_strings(item, "set", w),
                get_str(item, "shading", w, default="",
                        choices=("", "flat", "gouraud", "phong")) or None,
                get_str(item, "specular", w, default="", choices=("", "phong", "blinn"))
                or None))
        labels = [o.label for o in self.options]
        if len(set(labels)) != len(labels):
            raise where.fail("options", "two options have the same label")
        self.correct = get_str(raw, "correct", where, choices=tuple(labels))
        seed = int(hashlib.sha256(self.id.encode()).hexdigest()[:8], 16)
        self.order = list(np.random.default_rng(seed).permutation(len(self.options)))

    def shown(self) -> list[tuple[str, Option, Shot]]:
        """(letter, option, shot) in the order the student sees them."""
        out = []
        for letter, index in zip(LETTERS, self.order, strict=False):
            option = self.options[int(index)]
            out.append((letter, option, self.shot(tuple(option.set), option.shading,
                                                  option.specular)))
        return out

    def shots(self) -> dict[str, Shot]:
        return {shot.key: shot for _, _, shot in self.shown()}

    def compute(self) -> Expected:
        shown = self.shown()
        for a in range(len(shown)):
            for b in range(a + 1, len(shown)):
                diff = regions.rmse(self.images[shown[a][2].key], self.images[shown[b][2].key])
                if diff < 1e-5:
                    raise self.where.fail("options", f"'{shown[a][1].label}' and "
                                                     f"'{shown[b][1].label}' render the same "
                                                     "picture")
        letter = next(letter for letter, option, _ in shown if option.label == self.correct)
        return Expected(letter, None, {"labels": {letter: option.label
                                                  for letter, option, _ in shown}})

    def parse_answer(self, value: Any, where: Where) -> str:
        letters = LETTERS[:len(self.options)]
        if not isinstance(value, str) or value.strip().upper() not in letters:
            raise self.bad_answer(where, f"one of {', '.join(letters)}", value)
        return value.strip().upper()

    def judge(self, answer: str, expected: Expected):
        answer = self.parse_answer(answer, self.where)
        label = expected.detail["labels"][answer]
        return answer == expected.value, f"{answer} is '{label}'; the answer is " \
                                         f"{expected.value} ('{self.correct}')", {}

    def reveal_lines(self, expected: Expected, result: Result | None) -> list[str]:
        return [f"{letter}: {label}" for letter, label in expected.detail["labels"].items()]

    def reveal_images(self, expected: Expected, result: Result | None) -> dict:
        shown = self.shown()
        images = {f"{letter}: {option.label}": self.images[shot.key]
                  for letter, option, shot in shown}
        right = next(s for _, o, s in shown if o.label == self.correct)
        if result is not None and result.answer is not None and not result.passed:
            chosen = next(s for letter, _, s in shown if letter == result.answer)
            images["|yours - right|"] = regions.difference(self.images[chosen.key],
                                                           self.images[right.key])
        return images


# ---------------------------------------------------------------- match the target


class MatchTask(Task):
    """Match the target: set named parameters until the render matches a target image
    (RMSE of the linear images at most ``threshold``); each parameter's distance to the
    target value is reported."""

    KIND = "match"
    KEYS = {"params", "target", "start", "ranges", "threshold"}

    def parse(self, raw: dict, where: Where) -> None:
        self.params = get_strings(raw, "params", where, required=True)
        if not 1 <= len(self.params) <= 6:
            raise where.fail("params", "expected 1 to 6 dotted keys")
        n = len(self.params)
        self.target = get_numbers(raw, "target", where, length=n)
        self.start = get_numbers(raw, "start", where, length=n, required=False) \
            or list(self.target)
        ranges = raw.get("ranges")
        if ranges is None:
            self.ranges = [(min(0.0, t), max(1.0, 2 * t)) for t in self.target]
        else:
            if not isinstance(ranges, list) or len(ranges) != n or not all(
                    isinstance(r, list) and len(r) == 2 and all(is_number(v) for v in r)
                    and r[0] < r[1] for r in ranges):
                raise where.fail("ranges", f"expected {n} [low, high] pairs, low < high")
            self.ranges = [(float(a), float(b)) for a, b in ranges]
        self.threshold = get_number(raw, "threshold", where, lo=0.0)

    def items(self, values: list[float]) -> tuple[str, ...]:
        return tuple(f"{key}={_literal(v)}" for key, v in zip(self.params, values, strict=False))

    def target_shot(self) -> Shot:
        return self.shot(self.items(self.target))

    def answer_shot(self, values: list[float]) -> Shot:
        return self.shot(self.items(values))

    def shots(self) -> dict[str, Shot]:
        shot = self.target_shot()
        return {shot.key: shot}

    def compute(self) -> Expected:
        return Expected(list(self.target), self.threshold,
                        {"params": list(self.params)})

    def parse_answer(self, value: Any, where: Where) -> list[float]:
        n = len(self.params)
        if not isinstance(value, list) or len(value) != n or not all(is_number(v)
                                                                     for v in value):
            raise self.bad_answer(where, f"a list of {n} numbers ({', '.join(self.params)})",
                                  value)
        return [float(v) for v in value]

    def error_of(self, values: list[float]) -> float:
        """RMSE between the render with ``values`` and the target render."""
        shot = self.answer_shot(values)
        return regions.rmse(self.image(shot), self.image(self.target_shot()))

    def judge(self, answer: list[float], expected: Expected):
        err = self.error_of(answer)
        distance = {k: abs(a - t)
                    for k, a, t in zip(self.params, answer, self.target, strict=False)}
        ok = err <= self.threshold * (1 + 1e-9)
        far = ", ".join(f"{k} off by {_fmt(d)}" for k, d in distance.items())
        return ok, f"RMSE {err:.4g} (threshold {_fmt(self.threshold)}); {far}", \
            {"rmse": err, "distance": distance}

    def reveal_lines(self, expected: Expected, result: Result | None) -> list[str]:
        return ["target: " + ", ".join(f"{k} = {_fmt(v)}" for k, v in
                                      zip(self.params, self.target, strict=False))]

    def reveal_images(self, expected: Expected, result: Result | None) -> dict:
        target = self.image(self.target_shot())
        images = {"target": target}
        if result is not None and result.answer is not None:
            yours = self.image(self.answer_shot(result.answer))
            images["yours"] = yours
            images["|yours - target|"] = regions.difference(yours, target)
        return images


def _literal(value: float) -> str:
    return repr(int(value)) if float(value).is_integer() and abs(value) < 2**53 \
        else repr(float(value))


# ---------------------------------------------------------------- find the pixel

REGIONS = ("specular", "shadow", "mach")


class PixelTask(Task):
    """Find the pixel: click where something happens; graded by a region computed from the
    lab's renders (the brightest specular region, a shadow, the Mach bands), within
    ``tolerance`` pixels (Chebyshev distance)."""

    KIND = "pixel"
    KEYS = {"region", "fraction", "tolerance"}

    def parse(self, raw: dict, where: Where) -> None:
        self.region = get_str(raw, "region", where, choices=REGIONS)
        self.fraction = get_number(raw, "fraction", where, default=0.5, lo=0.0, hi=1.0)
        self.tolerance = float(get_int(raw, "tolerance", where, default=0, hi=64))

    def base_shot(self) -> Shot:
        return self.shot()

    def other_shot(self) -> Shot | None:
        if self.region == "specular":
            scene = self.scene()
            return self.shot(tuple(f"materials.{name}.ks=0" for name in scene.materials))
        if self.region == "shadow":
            return self.shot(("render.shadows=none",))
        return None

    def shots(self) -> dict[str, Shot]:
        shots = [self.base_shot(), self.other_shot()]
        return {s.key: s for s in shots if s is not None}

    def check(self) -> None:
        super().check()
        if self.region == "shadow" and self.scene().render.shadows == "none":
            raise self.where.fail("region", "'shadow' needs render.shadows = \"volumes\" "
                                            "in the task's scene")

    def mask(self) -> np.ndarray:
        base = self.images[self.base_shot().key]
        if self.region == "mach":
            return regions.mach_region(base, self.scene().render.background, self.fraction)
        other = self.images[self.other_shot().key]
        if self.region == "specular":
            return regions.specular_region(base, other, self.fraction)
        return regions.shadow_region(other, base, self.fraction)

    def compute(self) -> Expected:
        mask = self.mask()
        if not mask.any():
            raise self.where.fail("region", f"no '{self.region}' region in this image")
        center = regions.region_center(mask)
        return Expected(list(center), self.tolerance, {"pixels": int(mask.sum()),
                                                       "mask": mask})

    def parse_answer(self, value: Any, where: Where) -> tuple[int, int]:
        return check_pixel(value, where, "pixel", self.size)

    def judge(self, answer: tuple[int, int], expected: Expected):
        distance = regions.distance_to(expected.detail["mask"], answer)
        ok = distance <= self.tolerance
        where = "inside the region" if distance == 0 else f"{distance:g} px from it"
        return ok, f"{where} (tolerance {self.tolerance:g} px; region of " \
                   f"{expected.detail['pixels']} px around {expected.value})", \
            {"distance_px": distance}

    def reveal_lines(self, expected: Expected, result: Result | None) -> list[str]:
        what = {"specular": f"where the specular term reaches {self.fraction:g} of its peak",
                "shadow": f"where the shadow removes at least {self.fraction:g} of the "
                          "largest loss of light",
                "mach": f"where the intensity's slope jumps (|Laplacian| at least "
                        f"{self.fraction:g} of its peak)"}[self.region]
        return [f"the region: {what}: {expected.detail['pixels']} pixels around "
                f"{expected.value}"]

    def reveal_images(self, expected: Expected, result: Result | None) -> dict:
        base = self.images[self.base_shot().key]
        return {"image": base, "region": regions.overlay(base, expected.detail["mask"])}

    def answer_text(self, answer: Any) -> str:
        return f"[{answer[0]}, {answer[1]}]"


KINDS: dict[str, type[Task]] = {"number": NumberTask, "choice": ChoiceTask,
                                "match": MatchTask, "pixel": PixelTask}
