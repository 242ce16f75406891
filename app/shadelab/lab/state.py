"""The viewer's state: :class:`AppState` made of typed sub-states (``state.view``,
``state.probe``, ``state.offline``, ``state.studies``, ``state.walk``), with its undo history
(:mod:`shadelab.lab.history`) and the autosaved session (:mod:`shadelab.lab.session`).

Pure module (no GL, no GUI): the panels read and write an :class:`AppState`; the GL side keeps
its resources elsewhere (:mod:`shadelab.ui.viewport`, :mod:`shadelab.ui.gpu_side`). What the
panels ask of the GPU goes through ``AppState.gpu``, a :class:`shadelab.lab.gpu_queue.GpuQueue`
of numpy images, requests and plain results.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

from shadelab.errors import ShadeLabError
from shadelab.lab.gpu_queue import GpuQueue
from shadelab.lab.history import HISTORY_LIMIT, History  # noqa: F401 (re-exported)

# One file, written atomically; a damaged one is moved aside and never stops the viewer
# (shadelab.lab.session). Re-exported here, where the viewer has always found them.
from shadelab.lab.session import (  # noqa: F401
    SessionLoad,
    autosave_path,
    load_session,
    save_session,
    state_dir,
)
from shadelab.scene.model import Camera, Scene
from shadelab.scene.preset import clone_scene, load_preset, save_preset, scene_to_dict

if TYPE_CHECKING:  # types only (no import at run time: the GL side stays out of this module)
    import numpy as np

    from shadelab.lab.jobs import JobKind, JobRunner
    from shadelab.lab.lesson_file import LessonRun
    from shadelab.lab.pipeline_view import PipelineView
    from shadelab.lab.probe import ProbeResult
    from shadelab.lab.studies import StudyRun
    from shadelab.raytrace.tree import RayNode

COMPARE_VIEWS = (("flat", "phong"), ("gouraud", "phong"), ("phong", "phong"), ("phong", "blinn"))
def default_screenshot_dir() -> str:
    """Where S saves: $SHADELAB_SCREENSHOT_DIR, else the desktop's Pictures folder
    ($XDG_PICTURES_DIR or ~/Pictures) / ShadeLab (made on the first save)."""
    import os

    own = os.environ.get("SHADELAB_SCREENSHOT_DIR")
    if own:
        return own
    pictures = os.environ.get("XDG_PICTURES_DIR") or str(Path.home() / "Pictures")
    return str(Path(pictures) / "ShadeLab")


COMPARE_LABELS = ("Flat", "Gouraud", "Phong", "Blinn-Phong")
AUTOSAVE_INTERVAL = 1.0      # seconds between autosaves of a changed scene


# ---------------------------------------------------------------- sub-states


@dataclass
class ViewState:
    """How the viewport shows the scene: overlays, compare layout, resolution, presenter
    display options (shadelab.ui.presenter) and the viewport pipeline (shadelab.ui.pipelines)."""

    show_wireframe: bool = False
    show_normals: bool = False
    normal_length: float = 0.04       # glyph length, share of the scene's diagonal
    show_face_normals: bool = False   # one glyph per face, from its centroid
    show_normal_diff: bool = False    # heat map: angle between two vertex-normal rules
    normal_diff_modes: tuple[str, str] = ("average", "area")
    show_values: bool = True          # a figure's values (kd, ka, ks n, kt) under its objects
    show_names: bool = False          # every object's name and material in the viewport
    compare: bool = False
    diff_enabled: bool = False
    diff_pair: tuple[int, int] = (0, 2)   # indices into COMPARE_VIEWS
    diff_scale: float = 0.2           # heat map: this difference (x exposure) is full red
    presenter: bool = False
    render_scale: float = 1.0         # scene resolution / viewport resolution
    interactive_scale: float = 0.5    # the same while a slider or the camera is dragged
    show_help: bool = False
    legend_in_screenshot: bool = True
    viewport_size: tuple[int, int] = (0, 0)
    hide_panels: bool = False         # Tab: the viewport alone, with a caption
    fullscreen: bool = False          # F11 / --fullscreen: the monitor's resolution
    tonemap: str = "clamp"            # display: clamp | reinhard
    show_clipping: bool = False       # display: paint clipped pixels
    show_fps: bool = True             # fps / frame-time readout in the viewport
    fps_in_presenter: bool = False    # ... in presenter mode too (off: the class sees none)
    antialias: int = 1                # supersampling factor of the scene pass (1 or 2)
    msaa: int = 1                     # MSAA samples of the scene pass (1, 2, 4, 8)
    msaa_limit: int = 0               # the most the GL allows (0: not known yet)
    line_width: float = 0.0           # overlay lines, pixels (0: by the presenter scale)
    show_gizmos: bool = True          # light gizmos in the viewport
    gizmo_light: int = 0              # the light the viewport gizmo moves
    # Viewport pipeline: gouraud, phong, painter, radiosity, raytrace, pathtrace; "" = the
    # raster pipeline the scene's shading and visibility name
    pipeline: str = ""
    wipe: bool = False                # compare the pipeline with wipe_pipeline under one camera
    wipe_pipeline: str = "raytrace"
    wipe_position: float = 0.5        # share of the viewport's width left of the wipe line
    radiosity_patches: bool = False   # radiosity pipeline: draw the patch edges
    # The equation's terms switched off in the raster image and the probe (a click on the
    # caption's term, issue 22): names of shadelab.shading.codes.TERMS; a view setting, never
    # saved with the preset, back to none at every lesson step
    terms_off: frozenset = frozenset()
    pipeline_view: PipelineView | None = None  # the pipeline's jobs and images

    @property
    def fps_shown(self) -> bool:
        """The fps readout is drawn: asked for, and in presenter mode asked for there too."""
        return self.show_fps and (not self.presenter or self.fps_in_presenter)


@dataclass
class ProbeState:
    """The probed pixel and what the probe found there (shadelab.lab.probe)."""

    pixel: tuple[int, int] | None = None   # viewport pixel; None: no probe
    result: ProbeResult | None = None
    requested: bool = False           # probe again at the frame's end
    version: int = 0                  # bumped on every new probe result


@dataclass
class OfflineState:
    """The Offline render panel's job and what it left: the image's comparison with the raster
    view, a clicked pixel's ray tree, the solved radiosity triangles (shadelab.ui.offline)."""

    runner: JobRunner | None = None
    kind: int = 0                     # index into ``kinds``
    size: int = 256                   # offline panel image height, px
    spp: int = 16                     # samples per pixel (path tracer; Whitted anti-aliasing)
    comparison: dict | None = None    # error figures vs the raster view
    raster: np.ndarray | None = None  # (H, W, 3) raster image the job is compared with
    kinds: list[JobKind] | None = None  # shadelab.lab.jobs.available_jobs(), on first use
    version: int = -1                 # the JobRunner version last uploaded
    scene: Scene | None = None        # the Scene snapshot the last job rendered
    size_px: tuple = (0, 0)           # its image size (width, height)
    ray_tree: RayNode | None = None   # the ray tree of a clicked traced pixel
    ray_tree_pixel: tuple[int, int] | None = None  # (x, y) in the job image
    radiosity_soup: np.ndarray | None = None  # (3F, 6) float32 solved display triangles
    show_radiosity: bool = False      # draw the radiosity solution instead of the raster
    overlay_version: int = 0          # bumped when the ray tree or radiosity solution changes


@dataclass
class StudyState:
    """The Studies and Failure gallery panels (shadelab.ui.studies_panel)."""

    run: StudyRun | None = None       # made on first use
    index: int = 0                    # into shadelab.studies.STUDIES
    chart: int = 0                    # 0: the main chart; i: the result's i-th extra table
    plotted: int = 0                  # points the Studies chart drew last frame
    budget: float = 0.01              # auto quality's error budget (relative MSE)
    gallery_index: int = -1           # selected case of shadelab.studies.gallery.GALLERY
    gallery_opened: str = ""          # name of the last case opened in the viewer


@dataclass
class LessonState:
    """The lesson walked through with PageDown / PageUp (shadelab.lab.lesson)."""

    lesson: LessonRun | None = None
    focus_request: str = ""           # panels to bring to the front next frame (a,b,...)
    prefetch: object = None           # shadelab.lab.prefetch.Prefetch: the next step's job
    prefetch_enabled: bool = True     # (--no-prefetch: off, to measure without it)
    next_size: tuple | None = None    # the viewport's (w, h) at the next step (its caption)


# AppState's sub-states by their attribute names: ``state.view.compare``, ``state.probe.pixel``,
# ``state.offline.runner``, ``state.studies.index``, ``state.walk.lesson``.
SUB_STATES = {"view": ViewState, "probe": ProbeState, "offline": OfflineState,
              "studies": StudyState, "walk": LessonState}


# ---------------------------------------------------------------- the app state


@dataclass
class AppState:
    """Everything the panels show and edit; one instance per viewer window.

    Its parts are typed sub-states (:data:`SUB_STATES`): ``state.view``, ``state.probe``,
    ``state.offline``, ``state.studies``, ``state.walk``."""

    scene: Scene
    source: str                       # preset name or file the scene came from
    saved: dict = field(default_factory=dict)      # scene_to_dict at the last load/save
    initial_camera: Camera | None = None  # the preset's camera, for "reset view"
    history: History | None = None
    view: ViewState = field(default_factory=ViewState)
    probe: ProbeState = field(default_factory=ProbeState)
    offline: OfflineState = field(default_factory=OfflineState)
    studies: StudyState = field(default_factory=StudyState)
    walk: LessonState = field(default_factory=LessonState)
    # Messages
    error: str = ""                   # shown in the app (bad preset, bad mesh...)
    status: str = ""                  # last action ("saved ...", "screenshot ...")
    # Files
    preset_path: str = ""             # "Save" writes here
    open_path: str = ""               # text field of the open/save box
    screenshot_dir: str = field(default_factory=default_screenshot_dir)
    toast: tuple[str, float] = ("", 0.0)  # a message over the viewport until monotonic time
    screenshot_requested: str = ""    # a path: the viewport is written there next frame
    pending_open: str = ""            # a file asked for while there are unsaved edits
    # Bookkeeping
    dirty: bool = False               # unsaved changes (vs the preset or last save)
    edit_pending: bool = False        # an edit not yet in the undo history
    autosave_due: bool = False
    frame: int = 0
    scene_version: int = 0            # bumped by every scene edit and load
    gpu: GpuQueue = field(default_factory=GpuQueue)  # images and GPU work for the GL side

    @classmethod
    def from_scene(cls, scene: Scene, source: str, **kwargs) -> "AppState":
        from shadelab.lab.jobs import JobRunner

        state = cls(scene=scene, source=source, **kwargs)  # AppState's own fields
        state.saved = scene_to_dict(scene)
        state.initial_camera = clone_scene(scene).camera
        state.history = History(scene, state.file_meta())
        state.offline.runner = JobRunner()
        return state

    # ------------------------------------------------------------ edits
    def file_meta(self) -> dict:
        """Where the scene came from (what undoing a preset load goes back to)."""
        return {"source": self.source, "saved": self.saved, "preset_path": self.preset_path,
                "initial_camera": self.initial_camera}

    def mark_edited(self) -> None:
        """A parameter changed this frame; it joins the undo history once the edit ends."""
        self.scene_version += 1
        self.edit_pending = True
        self.autosave_due = True
        self.probe.requested = self.probe.pixel is not None

    def commit_edit(self) -> None:
        """Close an edit: snapshot for undo, recompute the unsaved flag."""
        self.edit_pending = False
        self.probe.requested = self.probe.pixel is not None  # again, at full resolution
        self.history.push(self.scene)
        self.dirty = scene_to_dict(self.scene) != self.saved

    def replace_scene(self, scene: Scene, source: str | None = None,
                      new_file: bool = False) -> None:
        """Show another scene (undo/redo keep the file; opening one resets everything)."""
        self.scene = scene
        self.scene_version += 1
        if new_file:
            self.source = source or scene.name
            self.saved = scene_to_dict(scene)
            self.initial_camera = clone_scene(scene).camera
            self.probe.pixel, self.probe.result = None, None
            self.preset_path = ""
            self.history.push(scene, self.file_meta())  # undo goes back to the last file
        self.dirty = scene_to_dict(scene) != self.saved
        self.autosave_due = True
        self.probe.requested = self.probe.pixel is not None

    def _go_to_snapshot(self, scene: Scene | None, what: str) -> None:
        if scene is None:
            return
        file = self.history.file()
        if file is not None and file["source"] != self.source:
            self.source, self.saved = file["source"], file["saved"]  # another file: its camera
            self.preset_path, self.initial_camera = file["preset_path"], file["initial_camera"]
            self.probe.pixel, self.probe.result = None, None
        else:
            scene.camera = self.scene.camera  # camera moves are not undone
        self.replace_scene(scene)
        self.status = what

    def undo(self) -> None:
        self._go_to_snapshot(self.history.undo(), "undo")

    def redo(self) -> None:
        self._go_to_snapshot(self.history.redo(), "redo")

    def request_open(self, path: str) -> None:
        """Open a preset or add a mesh; with unsaved edits, replacing the scene asks first
        (``pending_open``, answered by :func:`shadelab.ui.dialogs.draw_discard_question`)."""
        from shadelab.geometry.mesh import MESH_SUFFIXES
        from shadelab.lab.lesson_file import is_lesson_file, load_lesson

        if not self.dirty or Path(path).suffix.lower() in MESH_SUFFIXES:
            self.open_file(path)
            return
        try:  # a file that cannot open is said at once: no question about the edits first
            if is_lesson_file(path):
                load_lesson(path)
            else:
                load_preset(path)
        except ShadeLabError as exc:
            self.error = str(exc)
            return
        self.pending_open = path

    def open_file(self, path: str) -> bool:
        """A preset (.toml or a name) replaces the scene, a lesson file starts its walk at the
        first step; a mesh file is added to the scene."""
        from shadelab.geometry.mesh import MESH_SUFFIXES
        from shadelab.lab.lesson_file import is_lesson_file

        if Path(path).suffix.lower() in MESH_SUFFIXES:
            return self.add_mesh(path)
        if is_lesson_file(path):
            return self.open_lesson(path)
        return self.open_preset(path)

    def open_lesson(self, path: str) -> bool:
        """Walk the lesson in ``path`` (PageDown / PageUp): the viewer shows its first step at
        the frame's end (:func:`shadelab.lab.lesson.go_to`); a broken lesson is one line and
        keeps the scene."""
        from shadelab.lab.lesson_file import LessonRun, load_lesson

        try:
            lesson = load_lesson(path)
        except ShadeLabError as exc:
            self.error = str(exc)
            return False
        self.walk.lesson = LessonRun(lesson)
        self.error, self.status = "", f"lesson {lesson.name}: {len(lesson.steps)} steps"
        return True

    def add_mesh(self, path: str) -> bool:
        """Add a mesh file as an object, fitted in front of the camera; errors keep the scene."""
        import numpy as np

        from shadelab.geometry.mesh import load_mesh_file
        from shadelab.scene.model import Material, Object

        key = f"objects.{len(self.scene.objects)}.path"
        try:
            mesh = load_mesh_file(str(Path(path).resolve()), ".", key)
        except ShadeLabError as exc:
            self.error = str(exc)
            return False
        cam = self.scene.camera
        span = float(np.linalg.norm(np.subtract(cam.target, cam.eye)))
        lo, hi = np.asarray(mesh.bounds, dtype=np.float64)
        scale = 0.3 * span / max(float(np.max(hi - lo)), 1e-12)
        offset = np.asarray(cam.target, dtype=np.float64) - scale * (lo + hi) / 2.0
        if "mesh" not in self.scene.materials:
            self.scene.materials["mesh"] = Material(ka=0.1, kd=0.7, ks=0.3, n=20.0)
        self.scene.objects.append(Object(
            shape="mesh", name=Path(path).stem, material="mesh", path=str(Path(path).resolve()),
            scale=(scale,) * 3, translate=tuple(float(c) for c in offset), normals="angle"))
        self.mark_edited()
        self.commit_edit()
        self.error, self.status = "", f"added mesh {path}"
        return True

    def open_preset(self, name_or_path: str) -> bool:
        """Load a preset; on bad input show the error and keep the current scene."""
        try:
            scene = load_preset(name_or_path)
            from shadelab.geometry.mesh import scene_meshes

            scene_meshes(scene)  # mesh files must load too, before the scene is swapped
        except ShadeLabError as exc:
            self.error = str(exc)
            return False
        self.replace_scene(scene, name_or_path, new_file=True)
        if name_or_path.endswith(".toml"):
            self.preset_path = name_or_path
        self.error, self.status = "", f"opened {name_or_path}"
        return True

    def save_as(self, path: str) -> bool:
        """Save the scene as a preset file; errors are shown, nothing is half-written."""
        if not path:
            self.error = "save: enter a file name ending in .toml"
            return False
        if not path.endswith(".toml"):
            path += ".toml"
        try:
            save_preset(self.scene, path)
        except ShadeLabError as exc:
            self.error = str(exc)
            return False
        self.preset_path = path
        self.saved = scene_to_dict(self.scene)
        self.dirty = False
        self.error, self.status = "", f"saved {path}"
        return True

    def reset_view(self) -> None:
        import copy

        self.scene.camera = clone_scene(self.scene).camera if self.initial_camera is None \
            else copy.deepcopy(self.initial_camera)
        self.mark_edited()

    def title(self) -> str:
        """Window title: the preset, with a star while there are unsaved changes."""
        name = self.scene.name or Path(self.source).stem
        return f"ShadeLab - {name}{' *' if self.dirty else ''}"

