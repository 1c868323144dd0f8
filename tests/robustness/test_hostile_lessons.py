"""Hostile lesson files and checks: every one refused or handled cleanly.

Load-time problems are a :class:`BadLesson` naming ``file:line`` and the fix (the CLI
prints it on one line, exit 2); run-time problems of a check are a :class:`CheckError`
that :class:`Progress` keeps and the lesson panel shows once, in French; raw HTML in a
lesson never reaches viser's Markdown as HTML.
"""

from __future__ import annotations

import logging
import math
import os
import re
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from test_lessons import FakeController, Gui  # tests/ is on the path (conftest)

import sandbox.lessons.progress as progress_module
import sandbox.lessons.registry as lessons_module
from sandbox.cli import main
from sandbox.lessons import (
    MAX_LESSON_BYTES,
    MAX_LINE_CHARS,
    BadLesson,
    Catalogue,
    CheckError,
    Progress,
    compile_check,
    parse,
    render_text,
    validate,
)
from sandbox.web.panels import lesson as lesson_panel
from sandbox.web.panels.lesson import LessonPanel, status_text


def lesson_text(check: str = "bearing_A < 2 * initial(bearing_A)", *, body: str = "Texte.") -> str:
    """A valid rotor lesson whose single step has ``check`` on line 10."""
    return (
        "---\nscene: rotor\ntitle: T\nlevel: L1\n---\n\n"
        "## Step\npreset: mass1_g=10\nshow: bearing_A\n"
        f"check: {check}\nsolution: mass1_g=0\n\n{body}\n"
    )


CHECK_LINE = 10


def refused(path: Path, text: str | None = None) -> str:
    """The one-line refusal of ``path`` (written with ``text`` when given), within 2 s."""
    if text is not None:
        path.write_text(text, encoding="utf-8")
    start = time.perf_counter()
    with pytest.raises(BadLesson) as info:
        validate(parse(path))
    assert time.perf_counter() - start < 2.0
    message = str(info.value)
    assert "\n" not in message and "Traceback" not in message
    return message


# -- checks refused when the lesson loads ---------------------------------------------------
HOSTILE_CHECKS = [
    ("9**9**9 < bearing_A", r"exponent 3\.8742e\+08 is too large"),
    ("bearing_A < 9**9**9**9", "is too large"),
    ("bearing_A ** 1000 < 1", "exponent 1000 is too large"),
    ("max() < bearing_A", r"max\(\) takes 2 to 8 numbers, got 0"),
    ("min(bearing_A) < 1", r"min\(\) takes 2 to 8 numbers, got 1"),
    ("abs(1, 2) < bearing_A", r"abs\(\) takes one number, got 2"),
    ("(-8)**0.5 < bearing_A", "is not a real number"),
    ("bearing_A / 0 < 1", "division by zero"),
    ("bearing_A / (2 - 2) < 1", "division by zero"),
    ("0 ** -1 < bearing_A", "division by zero"),
    ("bearing_A.real < 1", "attribute access. is not allowed"),
    ("bearing_A.__class__ < 1", "attribute access. is not allowed"),
    ("__import__('os').system('ls') < 1", 'character "\'" is not allowed'),
    ("eval(bearing_A) < 1", "only abs, min, max and initial"),
    ("open(bearing_A) < 1", "only abs, min, max and initial"),
    ("min(*bearing_A, 1) < 1", "unpacking. is not allowed"),
    ("max(bearing_A, key=abs) < 1", "takes no keyword arguments"),
    ("initial(2 * bearing_A) < 1", r"initial\(\) takes one readout name"),
    ("abs < bearing_A", "abs is a function"),
    ("bearing_A < 1e999", "too large"),
    ("bearing_A < " + "9" * 200, "too large"),
    ("bearing_A < 1j", "only numbers are allowed"),
    ("bearing_A < True", "only numbers are allowed"),
    ("bearing_A", "a check is a condition"),
    ("1 < 2", "reads no readout"),
    ("not bearing_A", "combines conditions, not numbers"),
    ("(bearing_A < 1) * 2 < 1", "needs a number, not a condition"),
    ("bearing_A is 1", "use <, <=, >, >=, == or != to compare"),
    ("bearing_A // 2 < 1", "'//' is not allowed"),
    ("bearing_A if bearing_A else 1", "'if ... else' is not allowed"),
    ("[bearing_A][0] < 1", "character '\\[' is not allowed"),
    ("bearing_A < 1 # ` <img src=x onerror=alert(1)>", "character '#' is not allowed"),
    ("bearing_A < 1 ` <img src=x onerror=alert(1)> `", "character '`' is not allowed"),
    ("bearing_A < 1\x1b[2J", r"character '\\x1b' is not allowed"),
    ("bearing_A < (1", "invalid syntax"),
    ("(" * 900 + "bearing_A" + ")" * 900 + " < 1", "1813 characters"),
    ("-" * 250 + "bearing_A < 1", "more than 32 operations inside one another"),
    ("bearing_A < " + " + ".join(["bearing_A"] * 70), "characters; a check has at most 300"),
    ("min(" + ", ".join(["bearing_A"] * 30) + ") < 1", "more than 80 terms|at most 300"),
]


@pytest.mark.parametrize(("check", "needle"), HOSTILE_CHECKS)
def test_a_hostile_check_is_refused_with_file_line_and_fix(tmp_path, check, needle):
    path = tmp_path / "hostile.md"
    message = refused(path, lesson_text(check))
    if "\x1b" in check:  # refused with the file's every line, before it is read as a check
        assert message.startswith(f"{path}:{CHECK_LINE}: control character U+001B at column")
        return
    assert message.startswith(f"{path}:{CHECK_LINE}: bad check: ")
    assert re.search(needle, message), message


def test_the_fix_is_named_in_every_check_refusal():
    """Each refusal says what to write instead, not only what is wrong."""
    fixes = ("write", "use", "shorten", "name one", "simplify", "call it", "compare", "change")
    for check, _ in HOSTILE_CHECKS:
        with pytest.raises((ValueError, SyntaxError)) as info:
            compile_check(check)
        text = str(info.value)
        assert any(f in text for f in fixes), (check, text)


# -- files refused when the lesson loads ----------------------------------------------------
def test_a_file_above_the_size_bound_is_refused_without_reading_it_all(tmp_path):
    path = tmp_path / "big.md"
    with path.open("wb") as out:
        out.write(lesson_text().encode())
        out.write(b"x" * (MAX_LESSON_BYTES + 1))
    assert refused(path) == f"{path}:1: the file is larger than 64 KiB; split the lesson"


def test_a_line_above_the_length_bound_is_refused_at_its_line(tmp_path):
    path = tmp_path / "long.md"
    text = lesson_text(body="a" * (MAX_LINE_CHARS + 1))
    message = refused(path, text)
    assert message == (
        f"{path}:13: the line has {MAX_LINE_CHARS + 1} characters "
        f"(at most {MAX_LINE_CHARS}); break it"
    )


def test_a_file_that_is_not_utf8_is_refused_at_its_line(tmp_path):
    path = tmp_path / "latin1.md"
    path.write_bytes(lesson_text(body="Énergie").encode("latin-1"))
    assert refused(path) == f"{path}:13: the file is not UTF-8 text; save it as UTF-8"


def test_a_nul_byte_is_refused(tmp_path):
    path = tmp_path / "nul.md"
    message = refused(path, lesson_text(body="a\x00b"))
    assert message.startswith(f"{path}:13: NUL byte")


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs named pipes")
def test_a_named_pipe_is_refused_without_blocking(tmp_path):
    path = tmp_path / "pipe.md"
    os.mkfifo(path)
    assert refused(path) == f"{path}:1: not a regular file; a lesson is a Markdown text file"


def test_a_link_to_an_endless_device_is_refused(tmp_path):
    path = tmp_path / "zero.md"
    path.symlink_to("/dev/zero")
    assert refused(path).endswith("not a regular file; a lesson is a Markdown text file")


def test_a_folder_named_like_a_lesson_is_refused(tmp_path):
    path = tmp_path / "folder.md"
    path.mkdir()
    assert refused(path).startswith(f"{path}:1: not a regular file")


@pytest.mark.parametrize(
    ("edit", "line", "needle"),
    [
        (lambda s: s.replace("mass1_g=10", "mass1_g=nan"), 8, "expects a finite number"),
        (lambda s: s.replace("mass1_g=10", "mass1_g=1e999"), 8, "expects a finite number"),
        (lambda s: s.replace("mass1_g=10", "mass1_g=1e6"), 7, "preset"),
        (lambda s: s.replace("solution: mass1_g=0", "solution: mass1_g=-1e9"), 7, "preset"),
        (lambda s: s.replace("show:", "check: bearing_A < 1\nshow:"), 11, "given twice"),
        (lambda s: s.replace("show:", "question: Pourquoi ?\nshow:"), 9, "QUESTION | answer"),
        (lambda s: s.replace("## Step", "## "), 7, "a step needs a title"),
        (lambda s: s.replace("bearing_A < 2", "nope < 2"), 7, "no readout 'nope'; valid: "),
        (lambda s: s.replace("scene: rotor", "scene: <script>"), 2, "unknown scene '<script>'"),
        (lambda s: s.replace("level: L1", "level: L1\nnumber: 1e3"), 1, "expects an integer"),
    ],
)
def test_hostile_directives_are_refused_at_their_line(tmp_path, edit, line, needle):
    path = tmp_path / "bad.md"
    message = refused(path, edit(lesson_text()))
    assert message.startswith(f"{path}:{line}: ") and needle in message, message


def test_sandbox_list_names_the_bad_file_on_one_line_exit_2(tmp_path):
    """End to end, in a fresh interpreter: no traceback, one line, exit 2."""
    (tmp_path / "bad.md").write_text(lesson_text("9**9**9 < bearing_A"), encoding="utf-8")
    code = (
        "import sys, sandbox.lessons.registry as L\n"
        f"L.data_dir = lambda kind: __import__('pathlib').Path({str(tmp_path)!r})\n"
        "from sandbox.cli import main\n"
        "sys.exit(main(['list']))\n"
    )
    run = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, timeout=60, check=False
    )
    assert run.returncode == 2, run.stderr
    assert "Traceback" not in run.stderr
    lines = run.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"sandbox: error: {tmp_path / 'bad.md'}:10:")
    assert "exponent 3.8742e+08 is too large (at most ±64)" in lines[0]


@pytest.fixture
def lesson_folder(tmp_path, monkeypatch) -> Iterator[Path]:
    """``lessons/`` replaced by an empty ``tmp_path`` (the catalogue cache cleared)."""
    monkeypatch.setattr(lessons_module, "data_dir", lambda kind: tmp_path)
    lessons_module.catalogue.cache_clear()
    yield tmp_path
    lessons_module.catalogue.cache_clear()


def test_one_bad_file_leaves_the_others_to_the_web_and_fails_the_cli(lesson_folder, capsys):
    (lesson_folder / "good.md").write_text(lesson_text(), encoding="utf-8")
    (lesson_folder / "bad.md").write_text(lesson_text("max() < 1"), encoding="utf-8")
    found, errors = lessons_module.catalogue()
    assert list(found) == ["good"] and len(errors) == 1
    assert str(errors[0]).startswith(f"{lesson_folder / 'bad.md'}:10: bad check: max()")
    assert main(["list"]) == 2
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and err.startswith("sandbox: error: ") and "Traceback" not in err


# -- run time: live values that break a check -----------------------------------------------
@pytest.mark.parametrize(
    ("check", "values", "french"),
    [
        ("x * y < 1", {"x": 1e200, "y": 1e200}, "résultat trop grand (dépassement)"),
        ("x + y > 1", {"x": 1.5e308, "y": 1.5e308}, "résultat trop grand (dépassement)"),
        ("x / y < 1", {"x": 1.0, "y": 0.0}, "division par zéro"),
        ("x ** y < 1", {"x": -8.0, "y": 0.5}, "(-8) ** 0.5 n'est pas un nombre réel"),
        ("x ** y < 1", {"x": 2.0, "y": 1e9}, "exposant 1e+09 trop grand (au plus ±64)"),
        ("x ** 2 < 1", {"x": 1e200}, "résultat trop grand (dépassement)"),
        ("x ** y < 1", {"x": 0.0, "y": -2.0}, "division par zéro"),
        ("x < 1", {}, "grandeur « x » absente maintenant"),
        ("x < 1", {"x": "beaucoup"}, "grandeur « x » non numérique"),
        ("x < initial(y)", {"x": 1.0}, "grandeur « y » absente au début de l'étape"),
    ],
)
def test_live_values_that_break_a_check_raise_check_error_only(check, values, french):
    with pytest.raises(CheckError) as info:
        compile_check(check).evaluate(values, {})
    assert info.value.french == french


def test_huge_live_values_compute_only_the_operator_asked():
    """The issue's case: ``bearing_A - 1000 < 0`` once overflowed computing a**b."""
    check = compile_check("bearing_A - 1000 < 0")
    start = time.perf_counter()
    assert check.evaluate({"bearing_A": 1e308}, {}) is False
    assert check.evaluate({"bearing_A": 999.0}, {}) is True
    assert time.perf_counter() - start < 0.1


def test_nan_and_infinite_readouts_are_values_not_errors():
    check = compile_check("x < 1 or x > 2")
    assert check.evaluate({"x": math.nan}, {}) is False  # every comparison with NaN is false
    assert check.evaluate({"x": math.inf}, {}) is True


# -- the panel: shown once, in French, with file:line; never blocks silently ----------------
def open_panel(
    monkeypatch, tmp_path: Path, text: str, refused_files: tuple[BadLesson, ...] = ()
) -> tuple[LessonPanel, Gui]:
    path = tmp_path / "hostile.md"
    path.write_text(text, encoding="utf-8")
    lesson = parse(path)
    monkeypatch.setattr(
        lesson_panel, "catalogue", lambda: Catalogue({lesson.name: lesson}, refused_files)
    )
    gui = Gui()
    panel = LessonPanel(gui, FakeController({"mass1_g": 10.0}), lesson="hostile")  # type: ignore[arg-type]
    return panel, gui


def test_a_check_broken_by_live_values_is_shown_once_in_french_with_file_line(
    monkeypatch, tmp_path, caplog
):
    progress_module._REPORTED.clear()
    second = "\n## Suite\nshow: bearing_A\n\nFin.\n"
    text = lesson_text("bearing_A * 1e15 * 1e15 > 1") + second
    panel, _ = open_panel(monkeypatch, tmp_path, text)
    with caplog.at_level(logging.WARNING, logger="sandbox.lessons"):
        for _ in range(50):  # 50 refreshes with a value that overflows
            panel.refresh({"bearing_A": 1e300})
    status = panel.status.content
    assert status.startswith("**Vérification impossible** : résultat trop grand")
    assert "hostile\\.md:10" in status and "« Suivant ▶ »" in status
    assert panel.status.changes == 1  # shown once, not every frame
    assert len(caplog.records) == 1 and "hostile.md:10" in caplog.records[0].getMessage()
    panel._nav("Suivant ▶")  # the student goes on: the navigation never waits for the check
    panel.refresh({"bearing_A": 1e300})
    assert "étape 2/2" in panel.header.content and panel.status.content == ""


def test_a_check_that_passes_after_a_failure_still_counts(monkeypatch, tmp_path):
    panel, _ = open_panel(monkeypatch, tmp_path, lesson_text("bearing_A / initial(bearing_A) < 2"))
    panel.refresh({"bearing_A": 0.0})  # initial value 0: division by zero
    assert "division par zéro" in panel.status.content
    assert panel.progress is not None and panel.progress.error is not None
    panel.progress.initial = {"bearing_A": 1.0}
    panel.refresh({"bearing_A": 1.0})
    assert panel.status.content.startswith("**Réussi.**")


def test_a_readout_that_never_comes_is_reported_not_waited_for_forever():
    path = Path("absent.md")
    lesson = parse(path, lesson_text("nowhere < 1"))
    progress = Progress(lesson)
    results = [progress.observe({"bearing_A": 1.0}, {"mass1_g": 10.0}) for _ in range(10)]
    assert results == [None] * 10
    assert progress.error == "grandeur « nowhere » absente (absent.md:10)"
    assert status_text(progress, None).startswith("**Vérification impossible** : grandeur")


def test_lesson_titles_and_refused_files_are_shown_as_text(monkeypatch, tmp_path):
    evil = "<img src=x onerror=alert(1)>"
    text = lesson_text().replace("title: T", f"title: {evil}").replace("## Step", f"## {evil}")
    bad = BadLesson(f"{tmp_path}/x.md:3: bad check: <script>alert(1)</script>")
    panel, gui = open_panel(monkeypatch, tmp_path, text, (bad,))
    panel.refresh({"bearing_A": 1.0})
    shown = "\n".join(h.content for h in gui.markdowns)
    assert "<img" not in shown and "<script" not in shown
    assert "&lt;img src=x onerror=alert\\(1\\)&gt;" in panel.header.content
    assert panel.refused.content.startswith("**Fichier de leçon refusé**")


# -- lesson text: raw HTML shown as text, links only to http(s) ------------------------------
@pytest.mark.parametrize(
    "markdown",
    [
        "<img src=x onerror=alert(1)>",
        "<script>alert(1)</script>",
        "<IMG SRC=x ONERROR=alert(1)>",
        "<svg/onload=alert(1)>",
        "<a href='javascript:alert(1)'>clic</a>",
        "<!-- <img src=x onerror=alert(1)> -->",
        "$<img src=x onerror=alert(1)>$",
        "$\\text{<script>alert(1)</script>}$",
        "$a$<img src=x onerror=alert(1)>$b$",
    ],
)
def test_raw_html_in_lesson_text_is_shown_as_text(markdown):
    rendered = render_text(markdown)
    assert "<" not in rendered.replace("<i>", "").replace("</i>", "")
    assert "&lt;" in rendered


@pytest.mark.parametrize(
    "markdown",
    [
        "[clic](javascript:alert(1))",
        "[clic](JaVaScRiPt:alert(1))",
        "[clic]( javascript:alert(1))",
        "[clic](&#106;avascript:alert(1))",
        "![x](data:text/html;base64,PHNjcmlwdD4=)",
        "[a [b] c](vbscript:msgbox(1))",
        "[clic]($x$)",
    ],
)
def test_links_and_images_only_go_to_http_addresses(markdown):
    rendered = render_text(markdown)
    assert "](" not in rendered and "]\\(" in rendered


def test_reference_definitions_are_shown_as_text():
    rendered = render_text("[clic][1]\n\n[1]: javascript:alert(1)")
    assert "\\[1]: javascript" in rendered


def test_safe_links_and_the_course_formulas_are_kept():
    rendered = render_text(
        "Voir [le cours](https://example.org/cours) : $\\vec{\\Omega} \\wedge m \\omega^2 Y_{G}$."
    )
    assert "[le cours](https://example.org/cours)" in rendered
    assert "<i>Ω\u20d7 ∧ m ω<sup>2</sup> Y<sub>G</sub></i>" in rendered
