"""The shared check of viser's internals before the project changes its server."""

from __future__ import annotations


def test_a_viser_without_the_internals_is_left_as_it_is_with_one_warning(caplog):
    from sandbox.web.client.patches import internals_present

    def missing() -> bool:
        raise ImportError("no such module")

    assert internals_present(lambda: True, "unused")
    assert not internals_present(lambda: False, "events stay as they are")
    assert not internals_present(missing, "uploads are not capped")
    assert [r.getMessage() for r in caplog.records] == [
        "events stay as they are",
        "uploads are not capped",
    ]


def test_a_change_to_viser_is_made_once_and_only_when_its_internals_are_there(caplog):
    from sandbox.web.client.patches import install_once

    applied: list[str] = []
    name = "tests.web.test_patches.change"
    assert not install_once(name, lambda: False, "left as it is", lambda: applied.append("x"))
    assert applied == [] and [r.getMessage() for r in caplog.records] == ["left as it is"]
    assert install_once(name, lambda: True, "unused", lambda: applied.append("x"))
    assert install_once(name, lambda: True, "unused", lambda: applied.append("x"))
    assert applied == ["x"]  # once per process, however often the module asks


def test_the_projects_changes_to_viser_are_in_place_once_the_pages_can_be_built():
    from sandbox.web.client import uploads, wakeups, wire  # noqa: F401  (wire installs both)

    assert uploads.install() and wakeups.install()


def test_the_installed_viser_is_a_tested_one_with_every_piece_and_pyproject_says_so():
    from pathlib import Path

    from sandbox.web.client import viser_internals as vi

    assert vi.missing() == [] and vi.in_tested_range() and vi.version_line() is None
    pyproject = Path(__file__).resolve().parents[2] / "pyproject.toml"
    # the range the adapter checks is the one the package asks for
    assert f'"viser{vi.TESTED}"' in pyproject.read_text(encoding="utf-8")


def test_an_untested_viser_is_named_in_one_french_and_english_line_at_start(monkeypatch, caplog):
    from sandbox.web.client import viser_internals as vi

    assert [vi.in_tested_range(v) for v in ("1.0.9", "1.1.0", "1.1.7", "1.2.0", "2.0")] == [
        False,
        True,
        True,
        False,
        False,
    ]
    monkeypatch.setattr(vi, "version", lambda: "1.2.0")
    monkeypatch.setitem(vi.CHECKS, "upload cap", lambda: False)
    vi.warn_at_start()
    (line,) = [r.getMessage() for r in caplog.records]
    assert "\n" not in line
    assert "n'est pas une version testée : installez viser>=1.1,<1.2" in line
    assert "is not a tested release: install viser>=1.1,<1.2" in line
    assert "upload cap" in line


def test_viser_internals_are_reached_from_one_module_only():
    """Every private attribute of viser and every private viser module is used in
    sandbox/web/client/viser_internals.py only: a new viser release breaks one file,
    checked at start, never a classroom silently."""
    import ast
    from pathlib import Path

    import sandbox

    package = Path(sandbox.__file__).resolve().parent
    own = set()  # private names the project's own classes define
    trees = {}
    for path in package.rglob("*.py"):
        tree = ast.parse(path.read_text(encoding="utf-8"))
        trees[path] = tree
        for node in ast.walk(tree):
            if isinstance(node, ast.FunctionDef | ast.AsyncFunctionDef | ast.ClassDef):
                own.add(node.name)
            elif isinstance(node, ast.AnnAssign) and isinstance(node.target, ast.Name):
                own.add(node.target.id)  # a class's own attribute
            elif isinstance(node, ast.Attribute) and isinstance(node.value, ast.Name):
                if node.value.id == "self" and isinstance(node.ctx, ast.Store):
                    own.add(node.attr)
    found = []
    for path, tree in trees.items():
        if path.name == "viser_internals.py":
            continue
        for node in ast.walk(tree):
            where = f"{path.relative_to(package)}:{getattr(node, 'lineno', 0)}"
            if isinstance(node, ast.ImportFrom) and (node.module or "").startswith("viser"):
                names = [node.module or "", *(a.name for a in node.names)]
                if any(part.startswith("_") for n in names for part in n.split(".")):
                    found.append(f"{where} imports {names}")
            elif isinstance(node, ast.Attribute) and node.attr.startswith("_"):
                if node.attr.startswith("__") or node.attr in own:
                    continue
                if isinstance(node.value, ast.Name) and node.value.id in {"self", "cls", "os"}:
                    continue  # the project's own, or os._exit
                found.append(f"{where} .{node.attr}")
    assert not found, found
