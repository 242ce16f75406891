"""The layering of ARCHITECTURE.md §1, read from the source with ``ast``: every ``import`` and
``from ... import`` anywhere in a module (at the top, inside functions, under ``if``) counts,
lazy imports included, so a deferred import cannot hide a layer violation or a cycle."""

from __future__ import annotations

import ast
from pathlib import Path

ROOT = Path(__file__).resolve().parents[2] / "app"
PACKAGE = "shadelab"
PURE = ("scene", "shading", "geometry", "raytrace", "radiosity", "exercises")
GL_GUI = ("moderngl", "glfw", "imgui_bundle", "OpenGL")
UPPER = ("gl", "raster", "ui", "studies", "bench", "cli")


def module_name(path: Path) -> str:
    parts = list(path.relative_to(ROOT).with_suffix("").parts)
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def modules() -> dict[str, Path]:
    return {module_name(p): p for p in sorted((ROOT / PACKAGE).rglob("*.py"))}


def imported(name: str, path: Path) -> list[tuple[str, list[str], int]]:
    """(absolute module name, names taken from it, line) of every import in the module,
    wherever it stands (``import a.b`` gives ("a.b", [], line))."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    out = []
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"), str(path))):
        if isinstance(node, ast.Import):
            out += [(alias.name, [], node.lineno) for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                base = ".".join(parts[:len(parts) - node.level + 1] + ([base] if base else []))
            out.append((base, [alias.name for alias in node.names], node.lineno))
    return out


def internal_graph() -> dict[str, set[str]]:
    """shadelab module -> the shadelab modules it imports (submodules resolved to files)."""
    known = modules()
    graph: dict[str, set[str]] = {name: set() for name in known}
    for name, path in known.items():
        for base, names, _ in imported(name, path):
            # ``from pkg import mod`` imports the submodule pkg.mod where one exists; pkg
            # itself counts only for names that are not submodules (attributes of pkg)
            subs = [f"{base}.{n}" for n in names if f"{base}.{n}" in known]
            targets = subs if names and len(subs) == len(names) else [base, *subs]
            graph[name].update(t for t in targets if t in known and t != name)
    return graph


def find_cycle(graph: dict[str, set[str]]) -> list[str] | None:
    """One import cycle as [a, b, ..., a], or None (iterative depth-first search)."""
    state: dict[str, int] = {}  # 1 on the stack, 2 done
    for root in sorted(graph):
        if state.get(root):
            continue
        stack = [(root, iter(sorted(graph[root])))]
        path = [root]
        state[root] = 1
        while stack:
            node, children = stack[-1]
            child = next(children, None)
            if child is None:
                state[node] = 2
                stack.pop()
                path.pop()
            elif state.get(child) == 1:
                return path[path.index(child):] + [child]
            elif not state.get(child):
                state[child] = 1
                path.append(child)
                stack.append((child, iter(sorted(graph[child]))))
    return None


def is_under(name: str, prefix: str) -> bool:
    return name == prefix or name.startswith(prefix + ".")


def test_pure_packages_import_no_gl_gui_or_upper_layer():
    """scene, shading, geometry, raytrace, radiosity: no GL/GUI library and no gl, render,
    ui, studies or cli module, not even lazily inside a function."""
    bad = []
    for name, path in modules().items():
        if not any(is_under(name, f"{PACKAGE}.{p}") for p in PURE):
            continue
        for target, _, line in imported(name, path):
            forbidden = [lib for lib in GL_GUI if is_under(target, lib)] + \
                [up for up in UPPER if is_under(target, f"{PACKAGE}.{up}")]
            if forbidden:
                bad.append(f"{path.relative_to(ROOT)}:{line}: imports {target}")
    assert not bad, "pure layer imports GL/GUI or an upper layer:\n" + "\n".join(sorted(set(bad)))


def test_no_import_cycle_among_shadelab_modules():
    """Module-level and function-level imports together form an acyclic graph."""
    cycle = find_cycle(internal_graph())
    assert cycle is None, "import cycle: " + " -> ".join(cycle)


def test_cycle_finder_reports_a_cycle():
    graph = {"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}
    assert find_cycle(graph) == ["a", "b", "c", "a"]
    assert find_cycle({"a": {"b"}, "b": set()}) is None


# ---------------------------------------------------------------- the UI: panels vs GL side

GL = ("moderngl", "OpenGL", f"{PACKAGE}.gl", f"{PACKAGE}.raster")
# The viewer's GL side: the shell that owns the window, the viewport's passes, the queue's
# server and the pipelines' viewport drawing. Every other ui module (panels, state, jobs...)
# reaches the GPU only through ``state.gpu`` (shadelab.lab.gpu_queue).
GL_SIDE = tuple(f"{PACKAGE}.ui.{m}" for m in ("app", "viewport", "gpu_side", "pipeline_viewport"))


def test_panels_import_no_gl_module():
    """No ui module but the GL side imports moderngl, OpenGL, shadelab.gl, shadelab.raster or
    the GL side itself, not even lazily inside a function."""
    bad = []
    for name, path in modules().items():
        if not is_under(name, f"{PACKAGE}.ui") or name in GL_SIDE:
            continue
        for target, _, line in imported(name, path):
            if any(is_under(target, g) for g in GL + GL_SIDE[1:]):
                bad.append(f"{path.relative_to(ROOT)}:{line}: imports {target}")
    assert not bad, "a panel module imports GL:\n" + "\n".join(sorted(set(bad)))


def _field_types(cls) -> dict[str, object]:
    """``typing.get_type_hints`` of a dataclass, its ``if TYPE_CHECKING:`` imports included."""
    import importlib
    import typing

    module = importlib.import_module(cls.__module__)
    namespace = dict(vars(module))
    tree = ast.parse(Path(module.__file__).read_text(encoding="utf-8"))
    for node in ast.walk(tree):
        if isinstance(node, ast.If) and getattr(node.test, "id", "") == "TYPE_CHECKING":
            exec(compile(ast.Module(node.body, []), module.__file__, "exec"), namespace)
    return typing.get_type_hints(cls, globalns=namespace)


def _classes_in(hint) -> list[type]:
    import typing

    out, todo = [], [hint]
    while todo:
        h = todo.pop()
        todo += list(typing.get_args(h))
        if isinstance(h, type):
            out.append(h)
    return out


def test_app_state_holds_no_gl_object():
    """AppState, its sub-states and what the panels queue for the GPU: no ``gl`` field and no
    field whose type is a GL object (a moderngl, shadelab.gl, shadelab.raster or GL-side
    class)."""
    from shadelab.lab.gpu_queue import GpuQueue, Request, Texture
    from shadelab.lab.pipeline_view import PipelineView
    from shadelab.lab.state import SUB_STATES, AppState
    from shadelab.ui.radiosity_view import RadiosityView

    bad = []
    for cls in (AppState, *SUB_STATES.values(), GpuQueue, Request, Texture, PipelineView,
                RadiosityView):
        for name, hint in _field_types(cls).items():
            if name == "gl":
                bad.append(f"{cls.__name__}.gl")
            for t in _classes_in(hint):
                if any(is_under(t.__module__, g) for g in GL + GL_SIDE):
                    bad.append(f"{cls.__name__}.{name}: {t.__module__}.{t.__name__}")
    assert not bad, "GL in the panels' state:\n" + "\n".join(bad)


def test_gl_type_finder_sees_a_gl_class_inside_a_hint():
    """The check above can fail: a Viewport inside an optional or a dict is found."""
    from shadelab.ui.viewport import Viewport

    assert Viewport in _classes_in(Viewport | None)
    assert Viewport in _classes_in(dict[str, list[Viewport]])
    assert not any(is_under(t.__module__, "shadelab") for t in _classes_in(dict[str, int]))


def test_every_markdown_file_the_code_cites_is_in_the_repository():
    """Code and tests cite ARCHITECTURE.md (and README.md), never a guide outside the repo."""
    import re

    repo = ROOT.parent
    cited = {}
    for path in [*(ROOT / PACKAGE).rglob("*.py"), *(repo / "tests").rglob("*.py")]:
        for name in re.findall(r"\b([A-Z][A-Z_]+\.md)\b", path.read_text(encoding="utf-8")):
            cited.setdefault(name, path)
    assert "ARCHITECTURE.md" in cited
    missing = {name: str(path) for name, path in cited.items() if not (repo / name).is_file()}
    assert not missing


# ---------------------------------------------------------------- lab/: the viewer without GUI

VIEWER_LOGIC = ("lab",)


def test_the_viewer_logic_imports_no_gl_gui_or_ui_module():
    """lab/ (state, session, lessons, jobs, probe, recorder...) imports no GL or GUI library and
    no gl, raster, ui, bench or cli module, not even lazily: the API and the CLI may import it
    without a window. (The study runner starts ``shadelab.studies`` experiments as jobs.)"""
    bad = []
    for name, path in modules().items():
        if not any(is_under(name, f"{PACKAGE}.{p}") for p in VIEWER_LOGIC):
            continue
        for target, _, line in imported(name, path):
            forbidden = [lib for lib in GL_GUI if is_under(target, lib)] + \
                [up for up in UPPER if up != "studies" and is_under(target, f"{PACKAGE}.{up}")]
            if forbidden:
                bad.append(f"{path.relative_to(ROOT)}:{line}: imports {target}")
    assert not bad, "lab/ imports GL, GUI or an upper layer:\n" + "\n".join(sorted(set(bad)))


def test_only_ui_imports_imgui():
    """imgui_bundle and glfw are imported by ui/ alone (the bench's viewer subprocess drives the
    viewer through its command line)."""
    bad = []
    for name, path in modules().items():
        if is_under(name, f"{PACKAGE}.ui"):
            continue
        for target, _, line in imported(name, path):
            if is_under(target, "imgui_bundle") or is_under(target, "glfw"):
                bad.append(f"{path.relative_to(ROOT)}:{line}: imports {target}")
    assert not bad, "imgui outside ui/:\n" + "\n".join(sorted(set(bad)))
