"""The layer rules of docs/reference.md ("Development", "Layout"), checked on the source
with ``ast`` (no import is executed).

Layers, lowest first; a module may import its own layer and the layers below, never
one above (module-level, function-level and ``TYPE_CHECKING`` imports alike, and
``importlib.import_module("sandbox...")`` with a literal name):

0. base:      ``sandbox/__init__.py``, ``errors.py`` (the SandboxError hierarchy),
               ``data.py`` (where the MJCF, lesson and benchmark files are)
1. mechanics: ``sandbox/mechanics/`` (numpy only)
2. physics:   ``sandbox/physics/`` (MuJoCo: models, stepping, readouts)
3. scenes:    ``sandbox/scenes/`` (the registry and the scene specs)
4. runner:    ``sandbox/runner.py`` (the sampling loop of cli and bench)
5. tools:     ``recording/``, ``replay.py``, ``lessons/``, ``bench/`` (the work-precision
               grid and, in ``bench/classroom/``, the classroom load benchmark),
               ``sweep/`` (parameter studies), ``challenges.py``, ``accuracy.py`` (a
               setting on the scene's reference test)
6. web:       ``sandbox/web/`` (viser), itself in sub-layers, lowest first: client,
               view3d, loop (never viser), panels, video, page, views, serving, replay;
               web imports no scene module (scenes declare what the page draws)
7. cli:       ``sandbox/cli/``, ``launch.py``

Plus: mechanics imports neither MuJoCo nor viser; physics never imports viser; no import
circle anywhere (even inside a layer: the checker finds cycles, not only direction); an
import inside a function is kept only for an optional dependency or a lazy start-up path,
and says why in a comment on its line or the line above.
"""

from __future__ import annotations

import ast
import json
import subprocess
import sys
from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest

PACKAGE = Path(__file__).resolve().parents[1] / "sandbox"

LAYERS: tuple[tuple[str, tuple[str, ...]], ...] = (
    ("base", ("sandbox", "sandbox.errors", "sandbox.data", "sandbox.french")),
    ("mechanics", ("sandbox.mechanics",)),
    ("physics", ("sandbox.physics",)),
    ("scenes", ("sandbox.scenes",)),
    ("runner", ("sandbox.runner",)),
    (
        "tools",
        (
            "sandbox.recording",
            "sandbox.accuracy",
            "sandbox.challenges",
            "sandbox.bench",
            "sandbox.lessons",
            "sandbox.replay",
            "sandbox.sweep",
            "sandbox.written",  # how a readout is written, for every view
        ),
    ),
    ("web", ("sandbox.web",)),
    ("cli", ("sandbox.cli", "sandbox.launch")),
)
"""(layer, module prefixes), lowest first. A module belongs to its longest prefix."""

ORDER = " -> ".join(name for name, _ in LAYERS)

FORBIDDEN: dict[str, tuple[str, ...]] = {
    "mechanics": ("mujoco", "viser"),
    "physics": ("viser",),
}
"""Third-party packages a layer never imports (docs/reference.md, "Layout")."""


@dataclass(frozen=True)
class Import:
    """One import statement: where it is and the module it names."""

    path: Path
    line: int
    target: str


def module_name(path: Path, root: Path) -> str:
    """Dotted name of a source file under ``root`` (the package folder)."""
    parts = [root.name, *path.relative_to(root).with_suffix("").parts]
    if parts[-1] == "__init__":
        parts.pop()
    return ".".join(parts)


def layer_of(module: str) -> int | None:
    """Index in :data:`LAYERS` of a dotted module name (None: no layer)."""
    best, found = -1, None
    for index, (_, prefixes) in enumerate(LAYERS):
        for prefix in prefixes:
            if (module == prefix or module.startswith(prefix + ".")) and len(prefix) > best:
                best, found = len(prefix), index
    return found


def _resolve(name: str, root: Path) -> str:
    """``from a.b import c``: ``a.b.c`` when it is a module of the package, else ``a.b``."""
    rel = Path(*name.split(".")[1:])
    if (root / rel).with_suffix(".py").is_file() or (root / rel / "__init__.py").is_file():
        return name
    return name.rsplit(".", 1)[0]


def imports(path: Path, root: Path) -> Iterator[Import]:
    """Every import in the file, at any depth (functions, ``if TYPE_CHECKING``, ...)."""
    tree = ast.parse(path.read_text(), filename=str(path))
    here = module_name(path, root)
    package = here if path.name == "__init__.py" else here.rpartition(".")[0]
    for node in ast.walk(tree):
        if isinstance(node, ast.Import):
            for alias in node.names:
                yield Import(path, node.lineno, alias.name)
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                parts = parts[: len(parts) - (node.level - 1)]
                base = ".".join([*parts, base] if base else parts)
            for alias in node.names:
                full = f"{base}.{alias.name}"
                target = _resolve(full, root) if base.startswith(root.name) else base
                yield Import(path, node.lineno, target)
        elif isinstance(node, ast.Call):
            func = node.func
            called = getattr(func, "attr", None) or getattr(func, "id", None)
            if called in ("import_module", "__import__") and node.args:
                arg = node.args[0]
                if isinstance(arg, ast.Constant) and isinstance(arg.value, str):
                    yield Import(path, node.lineno, arg.value)


def sources(root: Path) -> list[Path]:
    return sorted(root.rglob("*.py"))


def upward_imports(root: Path) -> list[str]:
    """One message per import of a higher layer (file:line, the rule)."""
    out = []
    for path in sources(root):
        here = module_name(path, root)
        mine = layer_of(here)
        if mine is None:
            continue
        for imp in dict.fromkeys(imports(path, root)):  # one per line and target
            if imp.target.split(".")[0] != root.name:
                continue
            theirs = layer_of(imp.target)
            if theirs is not None and theirs > mine:
                out.append(
                    f"{path.relative_to(root.parent)}:{imp.line}: {here} ({LAYERS[mine][0]}) "
                    f"imports {imp.target} ({LAYERS[theirs][0]}); imports go only downward: "
                    f"{ORDER}"
                )
    return out


def forbidden_imports(root: Path) -> list[str]:
    """One message per import of a third-party package the layer must not use."""
    out = []
    for path in sources(root):
        here = module_name(path, root)
        mine = layer_of(here)
        if mine is None:
            continue
        banned = FORBIDDEN.get(LAYERS[mine][0], ())
        for imp in imports(path, root):
            if imp.target.split(".")[0] in banned:
                out.append(
                    f"{path.relative_to(root.parent)}:{imp.line}: {here} imports "
                    f"{imp.target}; {LAYERS[mine][0]} never imports {' nor '.join(banned)}"
                )
    return out


def import_graph(root: Path) -> dict[str, set[str]]:
    """Module -> the package modules it imports (at any depth, ``TYPE_CHECKING`` included)."""
    modules = {module_name(p, root): p for p in sources(root)}
    graph: dict[str, set[str]] = {m: set() for m in modules}
    for here, path in modules.items():
        for imp in imports(path, root):
            target = imp.target
            while target and target not in modules:  # ``a.b.name`` -> module ``a.b``
                target = target.rpartition(".")[0]
            if target and target != here and not here.startswith(target + "."):
                graph[here].add(target)
    return graph


def import_circles(root: Path) -> list[list[str]]:
    """Every strongly connected group of two or more modules (Tarjan), sorted."""
    graph = import_graph(root)
    index: dict[str, int] = {}
    low: dict[str, int] = {}
    stack: list[str] = []
    on_stack: set[str] = set()
    found: list[list[str]] = []

    def visit(v: str) -> None:
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in sorted(graph[v]):
            if w not in index:
                visit(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            group = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                group.append(w)
                if w == v:
                    break
            if len(group) > 1:
                found.append(sorted(group))

    for v in sorted(graph):
        if v not in index:
            visit(v)
    return sorted(found)


def local_imports(root: Path) -> list[str]:
    """One message per import inside a function with no comment saying why."""
    out = []
    for path in sources(root):
        lines = path.read_text().splitlines()
        tree = ast.parse("\n".join(lines), filename=str(path))
        for func in ast.walk(tree):
            if not isinstance(func, (ast.FunctionDef, ast.AsyncFunctionDef)):
                continue
            for node in ast.walk(func):
                if isinstance(node, (ast.Import, ast.ImportFrom)):
                    here = lines[node.lineno - 1]
                    above = node.lineno - 2  # a comment may head a block of imports
                    while above >= 0 and lines[above].strip().startswith(("import ", "from ")):
                        above -= 1
                    said = above >= 0 and lines[above].strip().startswith("#")
                    if "#" not in here and not said:
                        out.append(
                            f"{path.relative_to(root.parent)}:{node.lineno}: "
                            f"{here.strip()!r} inside {func.name}(); import at module level, "
                            "or say why it must wait (optional dependency, start-up cost) in "
                            "a comment on that line or the line above"
                        )
    return list(dict.fromkeys(out))  # nested functions walk the same import twice


WEB_LAYERS = (
    "client", "view3d", "loop", "panels", "video", "page", "views", "serving", "replay",
)  # fmt: skip
"""The sub-packages of ``sandbox/web``, lowest first (``sandbox/web/__init__.py`` says why)."""

SCENE_SHARED = ("registry", "measures", "revolutions")
"""Modules of ``sandbox/scenes`` that web may import: the registry and the measures the
scenes share, not a scene (the records, ``Scene`` and its page, are in physics)."""


def web_layer_of(module: str) -> int | None:
    """Index in :data:`WEB_LAYERS` of a module of ``sandbox.web`` (None: not in one)."""
    parts = module.split(".")
    if parts[:2] != ["sandbox", "web"] or len(parts) < 3:
        return None
    return WEB_LAYERS.index(parts[2]) if parts[2] in WEB_LAYERS else None


def web_upward_imports(root: Path) -> list[str]:
    """One message per web module not in a sub-layer, per import of a higher sub-layer,
    and per import of a scene module."""
    out = []
    for path in sources(root):
        here = module_name(path, root)
        if not here.startswith("sandbox.web.") and here != "sandbox.web":
            continue
        mine = web_layer_of(here)
        if mine is None and here != "sandbox.web":
            out.append(f"{path.relative_to(root.parent)}: {here} is in no sub-layer of web")
            continue
        for imp in dict.fromkeys(imports(path, root)):
            where = f"{path.relative_to(root.parent)}:{imp.line}: {here}"
            parts = imp.target.split(".")
            if mine == WEB_LAYERS.index("loop") and parts[0] == "viser":
                out.append(f"{where} imports {imp.target}; the loop never imports viser")
            if parts[:2] == ["sandbox", "scenes"] and len(parts) > 2:
                if parts[2] not in SCENE_SHARED:
                    out.append(
                        f"{where} imports the scene module {imp.target}; the scene declares "
                        "what the page needs (a field of its Scene record)"
                    )
                continue
            theirs = web_layer_of(imp.target)
            if mine is not None and theirs is not None and theirs > mine:
                out.append(
                    f"{where} ({WEB_LAYERS[mine]}) imports {imp.target} "
                    f"({WEB_LAYERS[theirs]}); inside web: {' -> '.join(WEB_LAYERS)}"
                )
    return out


def test_web_sub_layers_import_only_downward_and_no_scene_module():
    bad = web_upward_imports(PACKAGE)
    assert not bad, "\n".join(bad)


def test_the_web_checker_finds_upward_imports_and_scene_modules(tmp_path: Path):
    root = tmp_path / "sandbox"
    files = {
        "__init__.py": "",
        "scenes/__init__.py": "",
        "scenes/registry.py": "",
        "scenes/rotor.py": "",
        "web/__init__.py": "",
        "web/stray.py": "",
        "web/loop/__init__.py": "",
        "web/loop/session.py": "from sandbox.web.panels import plots\nimport viser\n",
        "web/panels/__init__.py": "",
        "web/panels/plots.py": (
            "from sandbox.scenes.registry import SCENES\nfrom sandbox.scenes import rotor\n"
            "from sandbox.web.loop import session\n"
        ),
    }
    for name, text in files.items():
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_text(text)
    assert [b.split(": ")[0] for b in web_upward_imports(root)] == [
        "sandbox/web/loop/session.py:1",  # loop imports panels
        "sandbox/web/loop/session.py:2",  # and viser
        "sandbox/web/panels/plots.py:2",  # a scene module
        "sandbox/web/stray.py",  # in no sub-layer
    ]


def test_no_import_circle():
    circles = import_circles(PACKAGE)
    assert not circles, "import circles (break them by moving the shared piece down): " + (
        "; ".join(" <-> ".join(c) for c in circles)
    )


def test_function_local_imports_say_why():
    bad = local_imports(PACKAGE)
    assert not bad, "\n".join(bad)


def test_every_module_has_a_layer():
    missing = [str(p) for p in sources(PACKAGE) if layer_of(module_name(p, PACKAGE)) is None]
    assert not missing, f"give these modules a layer in tests/test_layers.py LAYERS: {missing}"


def test_imports_go_only_downward():
    bad = upward_imports(PACKAGE)
    assert not bad, "\n".join(bad)


def test_mechanics_imports_neither_mujoco_nor_viser_and_physics_never_viser():
    bad = forbidden_imports(PACKAGE)
    assert not bad, "\n".join(bad)


@pytest.fixture
def toy(tmp_path: Path) -> Path:
    """A small ``sandbox`` tree with one hidden upward import of each kind."""
    root = tmp_path / "sandbox"
    files = {
        "__init__.py": "",
        "errors.py": "",
        "mechanics/__init__.py": "",
        "mechanics/torsor.py": "def f():\n    import mujoco\n",
        "physics/__init__.py": "",
        "physics/model.py": (
            "from typing import TYPE_CHECKING\n"
            "if TYPE_CHECKING:\n    from sandbox.scenes.base import Scene\n"
            "def resolve():\n    from sandbox.scenes import SCENES\n"
        ),
        "physics/readouts.py": "from . import model\nfrom .model import resolve\n",
        "scenes/__init__.py": "from sandbox.physics import readouts\n",
        "scenes/base.py": "",
        "web/__init__.py": "",
        "web/view.py": "import viser\nfrom sandbox.cli import main\n",
        "cli.py": "import importlib\nimportlib.import_module('sandbox.web.view')\n",
        "web/app.py": "from sandbox.web import follow\n",
        "web/follow.py": (
            "def serve():\n    # the pool is optional\n    import psutil\n"
            "    import os\n\n    from sandbox.web.app import main\n"
        ),
    }
    for name, text in files.items():
        (root / name).parent.mkdir(parents=True, exist_ok=True)
        (root / name).write_text(text)
    return root


def test_the_checker_finds_circles_and_silent_local_imports(toy: Path):
    assert import_circles(toy) == [
        ["sandbox.cli", "sandbox.web.view"],
        ["sandbox.physics.model", "sandbox.physics.readouts", "sandbox.scenes"],  # hidden ones
        ["sandbox.web.app", "sandbox.web.follow"],
    ]
    assert [b.split(": ")[0] for b in local_imports(toy)] == [
        "sandbox/mechanics/torsor.py:2",
        "sandbox/physics/model.py:5",
        "sandbox/web/follow.py:6",  # lines 3-4 are under their comment; line 6 is not
    ]


def test_the_checker_finds_hidden_upward_imports(toy: Path):
    bad = upward_imports(toy)
    assert [b.split(": ")[0] for b in bad] == [
        "sandbox/physics/model.py:3",  # TYPE_CHECKING
        "sandbox/physics/model.py:5",  # function-local
        "sandbox/web/view.py:2",
    ]
    assert "sandbox.scenes.base (scenes)" in bad[0] and "imports go only downward" in bad[0]
    assert forbidden_imports(toy) == [
        "sandbox/mechanics/torsor.py:2: sandbox.mechanics.torsor imports mujoco; "
        "mechanics never imports mujoco nor viser"
    ]


@pytest.mark.parametrize("index", range(len(LAYERS) - 1), ids=[n for n, _ in LAYERS[:-1]])
def test_importing_a_layer_loads_nothing_above_it(index: int):
    """At run time too (dynamic imports, registries): import every module of the layers
    up to ``index`` in a fresh interpreter; no module of a higher layer gets loaded."""
    mine = [
        module_name(p, PACKAGE)
        for p in sources(PACKAGE)
        if (layer_of(module_name(p, PACKAGE)) or 0) <= index
    ]
    script = (
        "import importlib, json, sys\n"
        f"for m in {mine!r}: importlib.import_module(m)\n"
        "print(json.dumps(sorted(sys.modules)))\n"
    )
    out = subprocess.run(
        [sys.executable, "-c", script], capture_output=True, text=True, check=True
    ).stdout
    loaded = json.loads(out.splitlines()[-1])
    above = [m for m in loaded if m.startswith("sandbox") and (layer_of(m) or 0) > index]
    assert not above, f"importing {LAYERS[index][0]} loads {above}"
    if LAYERS[index][0] == "mechanics":
        assert not [m for m in loaded if m.split(".")[0] in ("mujoco", "viser")]
    if LAYERS[index][0] == "physics":
        assert "viser" not in loaded
