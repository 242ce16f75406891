"""``shadelab view [PRESET]`` (also plain ``shadelab [PRESET]``): the interactive viewer."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from shadelab.errors import ShadeLabError
from shadelab.scene.preset import scene_to_dict

DEFAULT_PRESET = "lecture"
DEFAULT_WINDOW = "1600x900"  # the window's size before it is maximized
MAX_WINDOW = 16384           # a maximized window's side, at most (any monitor)
from shadelab.ui.display import NO_DISPLAY, check_display  # noqa: E402,F401


def add_parser(sub: argparse._SubParsersAction) -> None:
    p = sub.add_parser("view", help="open the interactive viewer (default preset: lecture)")
    p.add_argument("preset", nargs="?", metavar="PRESET",
                   help="preset name from presets/ or a path (default: the last session, or "
                        "lecture)")
    p.add_argument("--set", action="append", default=[], metavar="KEY=VALUE",
                   help="override a preset value, e.g. materials.white.kd=0.5")
    p.add_argument("--fresh", action="store_true", help="ignore the autosaved session")
    p.add_argument("--window", default=None, metavar="WxH",
                   help="window size (default: maximized on the monitor)")
    p.add_argument("--fullscreen", action="store_true",
                   help="fullscreen at the monitor's resolution (F11 toggles)")
    p.add_argument("--lesson", metavar="NAME", help="walk a lesson from presets/lessons/ "
                   "(PageDown / PageUp), e.g. phong-to-radiosity")
    p.add_argument("--step", type=int, default=1, metavar="N",
                   help="with --lesson: start at step N (1 = the first)")
    p.add_argument("--exercise", metavar="FILE", help="open this exercise (presets/exercises/ "
                   "name or .toml path) in the Exercise window")
    p.add_argument("--frames", type=int, default=0, metavar="N", help="quit after N frames")
    p.add_argument("--screenshot", metavar="PATH", help="write a PNG of the window at exit")
    p.add_argument("--compare", action="store_true", help="start in 2x2 compare mode")
    p.add_argument("--diff", action="store_true", help="with --compare: show the heat map")
    p.add_argument("--probe", metavar="X,Y", help="probe this viewport pixel at start")
    p.add_argument("--job", metavar="NAME", help="start this offline render at start "
                   "(e.g. 'reference', 'whitted', 'path', 'radiosity'); --frames counts "
                   "after it ends")
    p.add_argument("--show-radiosity", action="store_true",
                   help="with --job radiosity: draw the solution in the viewport when done")
    p.add_argument("--ray-tree", metavar="X,Y",
                   help="with --job whitted: draw the ray tree of this pixel of its image")
    p.add_argument("--focus", metavar="PANEL[,PANEL]", help="bring these panels' tabs to the "
                   "front (Scene, Lights, Materials, Objects, Equation, Studies, Gallery, ...)")
    p.add_argument("--study", metavar="NAME", help="run this study (quick) in the Studies panel "
                   "at start (shading, raytrace, radiosity, shadows); --frames counts after it")
    p.add_argument("--gallery", metavar="CASE", help="select this failure-gallery case and open "
                   "it in the viewer at start (e.g. gouraud-highlight)")
    p.add_argument("--pipeline", metavar="NAME",
                   help="start the viewport in this pipeline: gouraud, phong, painter, "
                        "radiosity, raytrace, pathtrace")
    p.add_argument("--presenter", action="store_true", help="large fonts for a projector")
    p.add_argument("--wireframe", action="store_true", help="show the wireframe")
    p.add_argument("--msaa", type=int, choices=(1, 2, 4, 8), default=1, metavar="N",
                   help="MSAA samples of the scene pass (1, 2, 4, 8; capped at what the GL "
                        "allows; the Display panel changes it)")
    p.add_argument("--normals", action="store_true", help="show normal glyphs")
    p.add_argument("--help-overlay", action="store_true", help="show the shortcut help")
    p.add_argument("--no-autosave", action="store_true", help="do not write the session")
    p.add_argument("--bench-json", help=argparse.SUPPRESS)
    p.add_argument("--bench-page-down", nargs="?", type=int, const=1, default=0,
                   help=argparse.SUPPRESS)
    p.add_argument("--no-prefetch", action="store_true",
                   help="with --lesson: do not render the next step's offline pipeline "
                        "ahead of time")
    p.set_defaults(run=run_view)


def check_job(name: str) -> None:
    """--job names an offline renderer (its pipeline name or a prefix of its label), checked
    before the window."""
    from shadelab.lab.jobs import available_jobs, find_job

    labels = [kind.label for kind in available_jobs()]
    if not name.strip() or find_job(name) is None:
        raise ShadeLabError(f"--job '{name}': expected one of reference, whitted, path, "
                            f"radiosity (a prefix of: {'; '.join(labels)})")


def _pixel(text: str, flag: str) -> tuple[int, int]:
    try:
        x, y = (int(v) for v in text.split(","))
    except ValueError:
        raise ShadeLabError(f"{flag} '{text}': expected an X,Y pixel, e.g. 300,200") from None
    if x < 0 or y < 0:
        raise ShadeLabError(f"{flag} '{text}': expected non-negative pixel coordinates")
    return x, y


from shadelab.lab.panel_names import PANEL_LABELS, unknown_panel  # noqa: E402

RAY_TREE_HEIGHT = 256    # the offline image's height (OfflineState.size) --ray-tree points in
RAY_TREE_MAX_ASPECT = 4  # its width: the viewport's aspect times that, at most this times it


def check_focus(focus: str) -> None:
    """--focus names dock windows by a label prefix or a word of one (ui.layout.focus_windows)."""
    word = unknown_panel(focus)
    if word is not None:
        raise ShadeLabError(f"--focus '{focus}': no panel '{word}'; expected one of "
                            f"{', '.join(PANEL_LABELS)}")


def _check_pixels(args: argparse.Namespace, window: tuple[int, int]):
    """(probe, ray_tree) pixels, each inside what it points in: the viewport (within the
    window) and the --job whitted image."""
    probe = _pixel(args.probe, "--probe") if args.probe else None
    if probe is not None:
        limit = window if args.window else (MAX_WINDOW, MAX_WINDOW)  # maximized: any monitor
        if probe[0] >= limit[0] or probe[1] >= limit[1]:
            where = f"the {limit[0]}x{limit[1]} window" if args.window \
                else f"any window (x, y < {MAX_WINDOW})"
            raise ShadeLabError(f"--probe '{args.probe}': outside {where}; expected a pixel "
                                "of the viewport")
    ray_tree = _pixel(args.ray_tree, "--ray-tree") if args.ray_tree else None
    if ray_tree is not None:
        from shadelab.lab.jobs import find_job

        kind = find_job(args.job) if args.job else None
        if kind is None or getattr(kind, "pipeline", "") != "raytrace":
            raise ShadeLabError(f"--ray-tree '{args.ray_tree}': only with --job whitted")
        if ray_tree[1] >= RAY_TREE_HEIGHT or \
                ray_tree[0] >= RAY_TREE_HEIGHT * RAY_TREE_MAX_ASPECT:
            raise ShadeLabError(f"--ray-tree '{args.ray_tree}': outside the job's image "
                                f"({RAY_TREE_HEIGHT} pixels high)")
    return probe, ray_tree


def _check_study_and_case(args: argparse.Namespace) -> None:
    """--study and --gallery name something that exists (one-line error otherwise)."""
    if args.study:
        from shadelab.studies import STUDIES

        names = [name for name, _ in STUDIES]
        if args.study not in names:
            raise ShadeLabError(f"--study '{args.study}': expected one of {', '.join(names)}")
    if args.gallery:
        from shadelab.studies.gallery import GALLERY

        names = [case.name for case in GALLERY]
        if args.gallery not in names:
            raise ShadeLabError(f"--gallery '{args.gallery}': expected one of "
                                f"{', '.join(names)}")


def saved_of(source: str) -> dict:
    """The preset a restored session came from, as saved (empty when it no longer loads)."""
    from shadelab.scene.preset import load_preset

    try:
        return scene_to_dict(load_preset(source))
    except ShadeLabError:
        return {}


def load_scene(args: argparse.Namespace, notes: list[str] | None = None):
    """(scene, source, restored): the autosaved session if it matches, else the preset.

    A damaged session never stops the viewer: it is moved aside and what was wrong is
    appended to ``notes`` (and printed), for the status line."""
    from shadelab.lab.state import load_session
    from shadelab.scene.preset import load_preset

    if not args.fresh and not args.set:
        session = load_session()
        if session.note:
            print(f"shadelab: {session.note}", file=sys.stderr)
            if notes is not None:
                notes.append(session.note)
        if session and args.preset in (None, session.source):
            print(f"shadelab: restored the autosaved session of '{session.source}' "
                  f"(--fresh to start from the preset)")
            return session.scene, session.source, True
    name = args.preset or DEFAULT_PRESET
    return load_preset(name, args.set), name, False


def _restored_meshes_or_preset(args: argparse.Namespace, scene, source: str,
                               notes: list[str]):
    """A restored session whose mesh file no longer reads (damaged since) falls back to the
    preset, the session kept aside; any other scene's broken mesh is the usual one-line error."""
    from shadelab.geometry.mesh import scene_meshes
    from shadelab.lab.session import autosave_path, move_aside

    try:
        scene_meshes(scene)
        return scene, source, True
    except ShadeLabError as exc:
        copy = move_aside(autosave_path())
        kept = f"kept as '{copy.name}'" if copy else "could not be moved aside"
        note = (f"the autosaved session's mesh does not load ({exc}); the session is {kept}; "
                "started from the preset").replace("\n", " ")
        print(f"shadelab: {note}", file=sys.stderr)
        notes.append(note)
    args.fresh = True
    scene, source, _ = load_scene(args)
    scene_meshes(scene)
    return scene, source, False


def run_view(args: argparse.Namespace) -> int:
    from shadelab.imageio import check_writable, parse_size

    window = parse_size(args.window or DEFAULT_WINDOW)
    check_writable(args.screenshot, "--screenshot")
    if args.screenshot and Path(args.screenshot).suffix.lower() != ".png":
        raise ShadeLabError(f"--screenshot '{args.screenshot}': expected a file name ending "
                            "in .png")
    if args.job is not None:
        check_job(args.job)
    probe, ray_tree = _check_pixels(args, window)
    if args.focus is not None:
        check_focus(args.focus)
    if args.frames < 0:
        raise ShadeLabError(f"--frames {args.frames}: expected a count >= 0")
    if args.bench_page_down < 0:
        raise ShadeLabError(f"--bench-page-down {args.bench_page_down}: expected a count >= 0")
    _check_study_and_case(args)
    if args.pipeline:
        from shadelab.pipelines import viewport_names

        if args.pipeline not in viewport_names():
            raise ShadeLabError(f"--pipeline '{args.pipeline}': expected one of "
                                f"{', '.join(viewport_names())}")
    run = None
    notes: list[str] = []   # a damaged autosaved session, for the status line
    if args.step != 1 and not args.lesson:
        raise ShadeLabError(f"--step {args.step}: only with --lesson NAME")
    if args.lesson:
        from shadelab.lab.lesson import LessonRun, load_lesson, step_scene

        run = LessonRun(load_lesson(args.lesson))  # every step checked: one-line error
        steps = len(run.lesson.steps)
        if not 1 <= args.step <= steps:
            raise ShadeLabError(f"--step {args.step}: expected 1 to {steps} "
                                f"(lesson '{args.lesson}' has {steps} steps)")
        first = run.lesson.steps[args.step - 1]
        scene, source, restored = step_scene(first), first.preset, False
    else:
        scene, source, restored = load_scene(args, notes)
    from shadelab.geometry.mesh import scene_meshes

    if restored:
        scene, source, restored = _restored_meshes_or_preset(args, scene, source, notes)
    else:
        scene_meshes(scene)  # a broken mesh file fails here, with its one-line reason
    if args.screenshot:  # not one of the scene's own files either
        from shadelab.scene.preset import scene_inputs

        inputs = scene_inputs(scene, source)
        if args.lesson:
            from shadelab.lab.lesson_file import resolve_lesson

            inputs.append(("lesson", resolve_lesson(args.lesson)))
        check_writable(args.screenshot, "--screenshot", inputs)
    exercise = None
    if args.exercise:
        from shadelab.exercises import load_exercise

        exercise = load_exercise(args.exercise)  # checked before the window: one-line error
    check_display()  # after the input: a bad flag or preset is named even without a display
    from shadelab.lab.state import AppState
    from shadelab.ui.app import ViewerOptions, run_viewer

    state = AppState.from_scene(scene, source)
    if restored:
        state.status = f"restored the autosaved session of '{source}'"
        state.saved = saved_of(source)  # the unsaved marker compares with the file, not
        state.dirty = state.saved != scene_to_dict(scene)  # with the restored session
        state.history.files[0] = state.file_meta()
    if notes:
        state.error = notes[-1]
    state.view.compare, state.view.diff_enabled = args.compare, args.diff
    state.view.presenter, state.view.show_help = args.presenter, args.help_overlay
    state.view.show_wireframe, state.view.show_normals = args.wireframe, args.normals
    if run is not None:   # after the view flags: the step's own toggles (show = [...]) win
        from shadelab.lab.lesson import go_to

        state.walk.lesson = run
        state.walk.prefetch_enabled = not args.no_prefetch
        go_to(state, args.step - 1)
    state.view.msaa = args.msaa
    if exercise is not None:
        from shadelab.ui.exercise_panel import open_exercise

        open_exercise(state, exercise)
    options = ViewerOptions(frames=args.frames, screenshot=args.screenshot or "",
                            window_size=window, probe=probe, job=args.job or "",
                            bench_json=args.bench_json or "", autosave=not args.no_autosave,
                            show_radiosity=args.show_radiosity, ray_tree=ray_tree,
                            focus=args.focus or "", study=args.study or "",
                            gallery=args.gallery or "", pipeline=args.pipeline or "",
                            fullscreen=args.fullscreen, page_down=args.bench_page_down,
                            maximized=args.window is None and not args.fullscreen)
    return run_viewer(state, options)
