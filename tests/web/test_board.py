"""The class board ("La classe"): rows read from what each student's page shows, merged
across worker processes, sorted, exported as CSV and shown escaped on the teacher's page,
in the default mode (one or two processes) and in follow mode."""

from __future__ import annotations

import csv
import io
import math
import re
import subprocess
import threading
import time
from collections.abc import Iterator
from pathlib import Path
from types import SimpleNamespace

import pytest
from conftest import choose, free_port, pause, wait_for

from sandbox.scenes import get_scene
from sandbox.web.panels.board import BOARD_FOLDER, BOARD_ORDER, CSV_BUTTON, NAME_LABEL
from sandbox.web.panels.board_rows import (
    KEEP_GONE,
    Board,
    Row,
    clean_name,
    from_wire,
    progress_of,
    to_wire,
)
from sandbox.web.panels.board_table import (
    CSV_COLUMNS,
    SORTS,
    board_html,
    csv_text,
    sort_rows,
    summary,
)
from sandbox.web.panels.student_rows import key_readout, student_row
from sandbox.web.serving.class_board import Classroom
from sandbox.web.serving.roster import Roster

# -- names ---------------------------------------------------------------------------------


def test_a_name_is_one_short_line_of_text():
    assert clean_name("  Zoé   Martin \n") == "Zoé Martin"
    assert clean_name("a\x00b\u202ec\u200bd") == "a b c d"
    assert len(clean_name("x" * 10_000)) == 40
    assert clean_name(42) == "" and clean_name(None) == ""


# -- rows across processes -----------------------------------------------------------------


def _row(key: str, joined: float, **kw: object) -> Row:
    return Row(key=key, joined=joined, **kw)  # type: ignore[arg-type]


def test_rows_survive_the_wire_and_a_bad_one_is_refused():
    row = _row("w0:3", 12.5, name="Zoé", step=2, steps=4, goal="in_progress", progress=0.4)
    assert from_wire(to_wire(row)) == row
    assert from_wire({"key": "w0:1", "joined": 1.0, "name": "<b>" + "x" * 99}).name == (
        "<b>" + "x" * 37
    )
    assert from_wire({"key": "w0:1", "joined": 1.0, "progress": 7.0}).progress == 1.0
    assert from_wire({"key": "w0:1", "joined": 1.0, "goal": "hack"}).goal == ""
    for bad in ({"key": 1, "joined": 1.0}, {"key": "k"}, {"key": "k", "joined": "1"}, [1], None):
        assert from_wire(bad) is None
    board = Board(5.0, (row,), left_out=2)
    assert Board.from_wire(board.wire()) == board
    assert Board.from_wire({"start": "x", "rows": []}) is None


def test_the_class_is_numbered_in_order_of_arrival_across_workers():
    roster = Roster(start=0.0, settle=1.5)
    roster.update(0, [_row("w0:1", 9.0), _row("w0:2", 8.0)], now=9.5)
    assert [r.display_name for r in roster.rows(now=9.4)] == ["Nouvel élève"] * 2
    # the other worker reports later a student who arrived between those two
    roster.update(1, [_row("w1:1", 8.5, name="Zoé")], now=9.8)
    rows = roster.rows(now=10.2)  # settled: who arrived up to 8.7
    assert [(r.key, r.number) for r in rows] == [("w0:2", 1), ("w1:1", 2), ("w0:1", 0)]
    assert [r.display_name for r in rows] == ["Élève 1", "Zoé", "Nouvel élève"]
    assert [r.number for r in roster.rows(now=11.0)] == [1, 2, 3]
    # a newcomer gets the next number; numbers never move
    roster.update(0, [_row("w0:1", 9.0), _row("w0:2", 8.0), _row("w0:9", 11.0)], now=11.0)
    assert {r.key: r.number for r in roster.rows(now=13.0)}["w0:9"] == 4
    assert {r.key: r.number for r in roster.rows(now=13.0)}["w0:2"] == 1


def test_a_student_who_left_stays_listed_as_gone_for_a_while():
    roster = Roster(start=0.0, stale=1e9)
    roster.update(0, [_row("w0:1", 1.0), _row("w0:2", 2.0)], now=10.0)
    roster.update(0, [_row("w0:2", 2.0)], now=11.0)
    (gone,) = [r for r in roster.rows(now=11.0) if not r.connected]
    assert gone.key == "w0:1" and gone.left == 11.0
    assert "1 élève connecté, 1 parti." == summary(roster.rows(now=12.0))
    assert "(parti)" in board_html(roster.rows(now=12.0))
    assert len(roster.rows(now=11.0 + KEEP_GONE - 1)) == 2
    assert [r.key for r in roster.rows(now=11.0 + KEEP_GONE + 1)] == ["w0:2"]


def test_a_worker_that_stops_reporting_or_restarts_has_its_students_gone():
    roster = Roster(start=0.0, stale=5.0)
    roster.update(0, [_row("w0:1", 1.0)], now=10.0)
    roster.update(1, [_row("w1:1", 1.5)], now=10.0)
    roster.update(0, [_row("w0:1", 1.0)], now=16.0)
    assert {r.key: r.connected for r in roster.rows(now=16.0)} == {"w0:1": True, "w1:1": False}
    roster.drop(0, now=17.0)
    assert not any(r.connected for r in roster.rows(now=17.0))


def test_the_board_is_bounded_and_says_how_many_it_leaves_out():
    roster = Roster(start=0.0, max_rows=3)
    roster.update(0, [_row(f"w0:{k}", float(k)) for k in range(5)], now=10.0)
    assert len(roster.rows(now=10.0)) == 3 and roster.left_out == 2
    assert "2 autres non affichés" in summary(roster.rows(now=10.0), roster.left_out)
    # a gone student makes room for a newcomer
    roster.update(0, [_row(f"w0:{k}", float(k)) for k in (1, 2)], now=11.0)
    roster.update(0, [_row(f"w0:{k}", float(k)) for k in (1, 2, 7)], now=12.0)
    assert {r.key for r in roster.rows(now=12.0)} == {"w0:1", "w0:2", "w0:7"}


# -- sorting, CSV, HTML --------------------------------------------------------------------

ROWS = (
    _row("a", 1.0, number=1, step=3, steps=4, goal="in_progress", progress=0.5),
    _row("b", 2.0, number=2, name="albert", step=1, steps=4, goal="in_progress", progress=0.9),
    _row("c", 3.0, number=3, name="Zoé", step=4, steps=4, goal="reached", progress=1.0),
    _row("d", 4.0, number=10, step=1, steps=4, goal="in_progress", progress=0.1, left=9.0),
)


@pytest.mark.parametrize(
    ("choice", "order"),
    [
        ("Arrivée", ["a", "b", "c", "d"]),
        ("Nom", ["b", "a", "c", "d"]),  # albert, Élève 1, Zoé; who left last
        ("Étape", ["b", "a", "c", "d"]),
        ("Progression", ["a", "b", "c", "d"]),
    ],
)
def test_sorting_puts_who_left_last(choice, order):
    assert [r.key for r in sort_rows(ROWS, SORTS[choice])] == order


def test_an_unknown_sort_names_the_valid_ones():
    with pytest.raises(ValueError, match="arrival, name, step, progress"):
        sort_rows(ROWS, "age")


def test_names_sort_as_people_read_them():
    rows = [_row(str(k), float(k), number=k) for k in (10, 2, 1)]
    assert [r.display_name for r in sort_rows(rows, "name")] == ["Élève 1", "Élève 2", "Élève 10"]


def test_the_csv_has_the_contract_columns_and_defuses_formulas():
    rows = [
        _row(
            "a",
            112.25,
            name="=HYPERLINK(1)",
            scene="rotor",
            lesson="equilibrage",
            step=4,
            steps=4,
            goal="in_progress",
            progress=0.4567,
            readout="bearing_A",
            value=54.4213,
            unit="N",
            number=1,
            challenge="rotor_balance",
            tries=3,
            solved_s=125.04,
        ),
        _row("b", 100.0, number=2, left=120.0),
        _row("c", 101.0, number=3, challenge="rotor_speed"),
    ]
    text = csv_text(rows, start=100.0)
    table = list(csv.reader(io.StringIO(text)))
    assert tuple(table[0]) == CSV_COLUMNS
    assert table[1] == [
        "'=HYPERLINK(1)",
        "true",
        "rotor",
        "equilibrage",
        "4",
        "in_progress",
        "0.457",
        "bearing_A",
        "54.4213",
        "N",
        "12.2",
        "rotor_balance",
        "true",
        "3",
        "125.0",
    ]
    assert table[2] == ["Élève 2", "false", "", "", "", "", "", "", "", "", "0.0", "", "", "", ""]
    assert table[3][-4:] == ["rotor_speed", "false", "0", ""]  # given, not tried


def test_the_table_escapes_names_and_shows_the_goal():
    rows = [
        _row("a", 1.0, number=1, name="<img src=x onerror=alert(1)>", step=2, steps=4),
        _row("b", 2.0, number=2, goal="in_progress", progress=0.42, label="Palier A", shown="5 N"),
        _row("c", 3.0, number=3, mode="follow"),
    ]
    html = board_html(rows)
    assert "<img" not in html and "&lt;img src=x onerror=alert(1)&gt;" in html
    assert 'aria-valuenow="42"' in html and "42 %" in html and "2/4" in html
    assert "suit la projection" in html and '<th class="v">Palier A</th>' in html
    assert "Aucun élève" in board_html(())
    # two readouts: each student's is written under their row, with its words
    mixed = [*rows, _row("d", 4.0, number=4, label="Balourd statique m·Y", shown="0,002 kg·m")]
    html = board_html(mixed)
    assert "Palier A : 5 N" in html and "Balourd statique m·Y : 0,002 kg·m" in html
    assert '<th class="v">' not in html


def test_a_goal_of_two_bars_counts_their_mean():
    assert progress_of([0.2, 0.6], "in_progress") == pytest.approx(0.4)
    assert progress_of([0.2, None], "reached") == 1.0
    assert math.isnan(progress_of([None], "in_progress"))


# -- a row from what the student's page shows ----------------------------------------------


def test_the_key_readout_is_what_the_step_checks_else_the_larger_bearing_force():
    values = {"bearing_A": 3.0, "bearing_B": 7.0, "omega": 1.0}
    assert key_readout("rotor", ("omega",), "static_unbalance", values) == "static_unbalance"
    assert key_readout("rotor", ("omega", "bearing_A"), "", values) == "bearing_B"
    assert key_readout("wheel_balancer", ("bearing_inner",), "", {}) == "bearing_inner"
    assert key_readout("compressor", ("speed", "T"), "", values) == "speed"
    assert key_readout("x", (), "", values) == ""


@pytest.fixture
def gui_server() -> Iterator[object]:
    import viser

    server = viser.ViserServer(port=free_port(), verbose=False)
    try:
        yield server
    finally:
        server.stop()


def test_a_row_reads_the_lesson_step_and_goal_the_page_shows(gui_server):
    from sandbox.physics.simulation import Simulation
    from sandbox.web.loop import Controller
    from sandbox.web.panels.lesson import LessonPanel
    from sandbox.web.panels.student_rows import Readouts as _Readouts
    from sandbox.web.panels.student_rows import Student as _Student

    controller = Controller(Simulation(get_scene("rotor")))
    panel = LessonPanel(gui_server.gui, controller, lesson="equilibrage")
    sim = controller.sim
    values = sim.readouts()
    panel.refresh(values)  # opens the lesson
    panel.go_to("equilibrage", 2)  # static balancing: static_unbalance < 1 % of its start
    panel.refresh(values)
    controller.drain()  # the step's presets
    start = sim.readouts()
    panel.refresh(start)  # the step's start
    now = dict(start, static_unbalance=start["static_unbalance"] * 0.1)
    panel.refresh(now)
    student = _Student(
        client=SimpleNamespace(client_id=7),  # type: ignore[arg-type]
        joined=100.0,
        scene="rotor",
        readouts=_Readouts.of(sim),
        view=SimpleNamespace(lesson=panel),
        field=SimpleNamespace(value="  Zoé\n"),  # type: ignore[arg-type]
    )
    row = student_row("p:7", student)
    assert (row.name, row.scene, row.lesson, row.step, row.steps) == (
        "Zoé",
        "rotor",
        "equilibrage",
        3,
        4,
    )
    assert row.goal == "in_progress"
    assert row.progress == pytest.approx(0.5)  # a tenth of the way to a hundredth: log scale
    assert row.readout == "static_unbalance"  # what the step checks
    assert row.value == pytest.approx(now["static_unbalance"]) and row.unit == "kg·m"
    assert row.shown.endswith("\u00a0kg·m") and "," in row.shown
    # free exploration: the larger bearing force (A: 54 N, B: 15 N), no step
    panel.go_to(None)
    panel.refresh(now)
    free = student_row("p:7", student)
    assert (free.step, free.goal, free.readout, free.label) == (0, "", "bearing_A", "Palier A")
    assert free.shown == "54,42\u00a0N"
    assert math.isnan(free.progress)


def test_a_classroom_forgets_a_browser_that_left_and_publishes_the_rest():
    here = {1, 2}
    published: list[tuple[list[dict[str, object]], bool]] = []

    class Hub:
        def publish(self, rows, wants, load=None):
            published.append((rows, wants))

    from sandbox.physics.simulation import Simulation

    room = Classroom(lambda cid: cid in here, clock=lambda: 50.0)
    room.relay(Hub(), source="w1")
    sim = Simulation(get_scene("rotor"))
    for cid in (1, 2):
        room.student(SimpleNamespace(client_id=cid), sim)  # type: ignore[arg-type]
    room.tick()
    assert [r["key"] for r in published[-1][0]] == ["w1:1", "w1:2"] and not published[-1][1]
    here.discard(1)
    room.tick()
    assert [r["key"] for r in published[-1][0]] == ["w1:2"] and room.students() == 1


# -- the pages -----------------------------------------------------------------------------


class FakeStudent:
    """A browser as the classroom benchmark plays it: viser's protocol on a websocket,
    every message read (a client that stops reading is dropped by the server's pings);
    types ``name`` in "Votre prénom" once the box arrives."""

    def __init__(self, url: str, name: str | None = None) -> None:
        import viser
        from websockets.sync.client import connect

        from sandbox.bench.classroom import camera_message

        self.name = name
        self.typed = False
        self.ws = connect(
            url,
            subprotocols=[f"viser-v{viser.__version__}"],  # type: ignore[list-item]
            open_timeout=30,
            max_size=None,
        )
        self.ws.send(camera_message())
        self.thread = threading.Thread(target=self._read, daemon=True)
        self.thread.start()

    def _read(self) -> None:
        from sandbox.bench.classroom import find_gui, gui_message, unpack

        try:
            for raw in self.ws:
                if self.name is None or self.typed or not isinstance(raw, bytes):
                    continue
                try:
                    box = find_gui(unpack(raw), "Text", NAME_LABEL)
                except Exception:  # a message not worth decoding: keep reading
                    continue
                if box is not None:
                    self.ws.send(gui_message(box["uuid"], self.name))
                    self.typed = True
        except Exception:
            pass  # closed

    def close(self) -> None:
        self.ws.close()


def _board_text(page) -> str:
    board = page.locator(".sandbox-board")
    return board.last.inner_text() if board.count() else ""


def _shows(page, text: str) -> bool:
    return page.get_by_text(text, exact=True).count() > 0


@pytest.fixture
def served_class() -> Iterator[object]:
    from sandbox.web.serving.app import start

    app = start("rotor", port=free_port(), open_message=False, token="tok-1")
    try:
        yield app
    finally:
        app.stop()


def test_only_the_secret_path_opens_the_teacher_s_page(served_class):
    import urllib.error
    import urllib.request

    with urllib.request.urlopen(served_class.teacher_url, timeout=10) as page:
        assert page.status == 200 and b"<html" in page.read(2000).lower()
    with pytest.raises(urllib.error.HTTPError):
        urllib.request.urlopen(served_class.url + "/prof/guess", timeout=10)


def test_the_default_mode_prints_a_teacher_link(capsys):
    from sandbox.web.serving.app import start

    app = start("rotor", port=free_port(), token="tok-2")
    try:
        out = capsys.readouterr().out
        assert f"teacher link (keep it to yourself) {app.url}/prof/tok-2" in out
        assert app.teacher_url == f"{app.url}/prof/tok-2"
    finally:
        app.stop()


@pytest.mark.browser
@pytest.mark.slow  # one Chromium page, two websocket students: about 20 s
def test_the_teacher_downloads_the_board_and_reads_names_escaped(open_page, served_class):
    app = served_class
    url = app.url.replace("http", "ws")
    name = "Zoé <img src=x onerror=alert(1)>"
    students = [FakeStudent(url, name)]
    try:
        teacher = open_page(app.teacher_url)
        teacher.get_by_text(BOARD_FOLDER, exact=True).last.wait_for(timeout=60_000)
        assert wait_for(lambda: name in _board_text(teacher), 60), _board_text(teacher)
        assert teacher.locator(".sandbox-board img").count() == 0  # shown, never run
        students.append(FakeStudent(url))  # arrives second: "Élève 2"
        assert wait_for(lambda: "Élève 2" in _board_text(teacher), 30), _board_text(teacher)
        assert _shows(teacher, "2 élèves connectés.")
        # the second student's first numbers reach the board within its next second
        assert wait_for(lambda: _board_text(teacher).count("\xa0N") >= 2, 30), _board_text(teacher)
        with teacher.expect_download(timeout=30_000) as info:
            teacher.get_by_role("button", name=CSV_BUTTON).click()
        assert info.value.suggested_filename.endswith(".csv")
        text = Path(info.value.path()).read_text(encoding="utf-8")
        table = list(csv.DictReader(io.StringIO(text)))
        assert [r["name"] for r in table] == [name, "Élève 2"]  # by arrival
        assert [(r["scene"], r["connected"], r["unit"]) for r in table] == [
            ("rotor", "true", "N")
        ] * 2
        assert {r["readout"] for r in table} <= {"bearing_A", "bearing_B"}
        assert all(float(r["value"]) > 0 and float(r["joined_s"]) >= 0 for r in table)
        # sorted by name, "Élève 2" comes before "Zoé"
        choose(teacher, "Trier par", "Nom")
        assert wait_for(
            lambda: _board_text(teacher).index("Élève 2") < _board_text(teacher).index("Zoé")
        )
        # a student leaves: listed as gone
        students[1].close()
        assert wait_for(lambda: "Élève 2 (parti)" in _board_text(teacher), 30)
        assert wait_for(lambda: _shows(teacher, "1 élève connecté, 1 parti."))
    finally:
        for s in students:
            s.close()


def _start_workers(tmp_path: Path) -> tuple[subprocess.Popen[str], int, str]:
    from conftest import serve_workers

    proc, port = serve_workers(tmp_path)
    assert isinstance(proc, subprocess.Popen) and proc.stdout is not None
    first = proc.stdout.readline()
    assert f"http://127.0.0.1:{port} by 2 worker processes" in first, first
    second = proc.stdout.readline()
    prefix = "sandbox: teacher link (keep it to yourself) "
    assert second.startswith(prefix + f"http://127.0.0.1:{port}/prof/"), second
    return proc, port, second.removeprefix(prefix).strip()


def _stop(proc: subprocess.Popen[str]) -> None:
    import os
    import signal

    with_group = os.getpgid(proc.pid)
    os.killpg(with_group, signal.SIGTERM)
    try:
        proc.wait(15)
    except subprocess.TimeoutExpired:
        os.killpg(with_group, signal.SIGKILL)
        proc.wait(5)


@pytest.mark.browser
@pytest.mark.slow  # two worker processes, one Chromium page, six websocket students: ~30 s
def test_the_board_lists_the_students_of_both_workers(open_page, tmp_path):
    proc, port, teacher_url = _start_workers(tmp_path)
    students: list[FakeStudent] = []
    try:
        teacher = open_page(teacher_url)
        teacher.get_by_text(BOARD_FOLDER, exact=True).last.wait_for(timeout=60_000)
        url = f"ws://127.0.0.1:{port}"
        students = [FakeStudent(url, "Zoé" if k == 3 else None) for k in range(6)]
        # the front gave each worker three students (the teacher's page is on one): six
        # rows are the students of both, numbered once every worker has reported them

        def listed() -> bool:
            text = _board_text(teacher)
            return "Zoé" in text and len(re.findall(r"Élève \d+\t", text)) == 5

        assert wait_for(lambda: _shows(teacher, "6 élèves connectés.") and listed(), 60), (
            _board_text(teacher)
        )
    finally:
        for s in students:
            s.close()
        _stop(proc)


@pytest.mark.browser
@pytest.mark.slow  # two Chromium pages: about 30 s
def test_follow_mode_lists_followers_with_their_name_and_fits_the_buttons(open_page):
    from sandbox.web.serving.app import start
    from sandbox.web.serving.follow import OWN, SEND_STEP, SEND_VALUES

    app = start("rotor", port=free_port(), open_message=False, follow=True, token="t-3")
    try:
        teacher = open_page(app.teacher_url)
        teacher.get_by_text(BOARD_FOLDER, exact=True).last.wait_for(timeout=60_000)
        pause(teacher)  # names and buttons: the followers' projection may stand still
        student = open_page(app.url)
        label = student.get_by_text(NAME_LABEL, exact=True).last
        label.wait_for(timeout=60_000)
        box = student.locator("div.mantine-Flex-root", has=label).last.locator("input").first
        box.fill("Zoé")
        assert wait_for(lambda: "Zoé" in _board_text(teacher), 30), _board_text(teacher)
        assert "suit la projection" in _board_text(teacher)
        # the name stays when the student takes a simulation of their own
        student.get_by_role("button", name=OWN).click()
        assert wait_for(lambda: "suit la projection" not in _board_text(teacher), 30)
        assert "Zoé" in _board_text(teacher)
        # the send buttons keep their whole label on one line at 24 px on a 1280x720 page
        # (the former "Envoyer mes réglages aux élèves" took two lines, 58 px high)
        teacher.set_viewport_size({"width": 1280, "height": 720})
        choose(teacher, "Panneau affiché", "Projecteur")
        choose(teacher, "Taille du texte", "24 px")
        for name in (SEND_VALUES, SEND_STEP):
            button = teacher.get_by_role("button", name=name)
            assert wait_for(
                lambda b=button: (
                    b.evaluate(
                        "e => getComputedStyle(e.querySelector('.mantine-Button-label')).fontSize"
                    )
                    == "24px"
                )
            )
            width, room, height = button.evaluate(
                "e => { const l = e.querySelector('.mantine-Button-label');"
                " return [l.scrollWidth, l.clientWidth, l.scrollHeight]; }"
            )
            assert width <= room + 1 and height < 1.6 * 24, (name, width, room, height)  # one line
    finally:
        app.stop()


def test_a_board_is_shown_sorted_as_the_teacher_chose(gui_server):
    from sandbox.web.panels.board import BoardPanel

    client = SimpleNamespace(gui=gui_server.gui, send_file_download=lambda *a, **k: None)
    panel = BoardPanel(client)  # type: ignore[arg-type]
    board = Board(0.0, ROWS)
    panel.show(board)
    assert panel.table.content.index("Zoé") > panel.table.content.index("albert")
    panel._choose("Progression")
    assert panel.by == "progress"
    panel._choose("<script>")  # a crafted choice: ignored, the control put back
    assert panel.by == "progress" and panel.sort.value == "Progression"
    lines = panel.csv().splitlines()
    assert lines[0] == ",".join(CSV_COLUMNS) and len(lines) == 1 + len(ROWS)


# -- challenges on the board -------------------------------------------------------------
def test_a_run_travels_with_the_board_and_a_crafted_one_is_dropped():
    from sandbox.web.panels.board_rows import Run

    run = Run("abc", "rotor_balance", 12.5, 0.0)
    board = Board(1.0, (_row("a", 2.0, challenge="rotor_balance", tries=2, solved_s=30.0),), 0, run)
    back = Board.from_wire(board.wire())
    assert back is not None and back.run == run and back.rows[0].tries == 2
    for bad in ({"id": "", "name": "x", "started": 1.0}, {"id": 3, "name": "x", "started": 1.0},
                {"id": "a", "name": "x", "started": math.nan}, "run"):  # fmt: skip
        assert Board.from_wire({**board.wire(), "run": bad}).run is None  # type: ignore[union-attr]


def test_during_a_challenge_the_table_shows_who_solved_it_and_sorts_fastest_first():
    rows = [
        _row("a", 1.0, number=1, name="Lou", challenge="rotor_balance", tries=3, solved_s=125.0),
        _row("b", 2.0, number=2, name="Ana", challenge="rotor_balance", tries=0),
        _row("c", 3.0, number=3, name="Max", challenge="rotor_balance", tries=1, solved_s=45.0),
        _row("d", 4.0, number=4, name="Zoé", challenge="rotor_balance", tries=5),
    ]
    html = board_html(rows)
    assert "<th>Défi</th>" in html and "<th>Étape</th>" not in html
    assert "réussi</span> en 2 min 05 s, 3 essais" in html and "aucun essai" in html
    assert [r.name for r in sort_rows(rows, SORTS["Défi"])] == ["Max", "Lou", "Zoé", "Ana"]


def test_a_challenge_announced_in_one_process_reaches_its_board_at_once():
    from sandbox.web.panels.board_rows import Run
    from sandbox.web.serving.class_board import LocalHub

    got: list[Board] = []
    hub = LocalHub(0.0, got.append, clock=lambda: 5.0)
    hub.announce(Run("r", "rotor_balance", 5.0))
    hub.publish([to_wire(_row("a", 1.0))], wants=True)
    assert [b.run.name if b.run else None for b in got] == ["rotor_balance"] * 2


WHO = "0123456789abcdef01234567"


def _roster_rows(app) -> list:
    return list(app.classroom.hub.roster.rows(time.time()))


def test_a_tab_keeps_its_row_and_its_name_across_a_reconnection(served_class):
    """A page's websocket carries the tab's key and the name its browser kept (the page's
    script sets them): the name box is filled with it, and a reload (a new connection with
    the same key) keeps the student's one row, number and name, not a « (parti) » row
    beside a new « Élève 2 »."""
    from sandbox.web.page.link import NAME_KEY, WHO_KEY

    app = served_class
    url = app.url.replace("http", "ws") + f"/?{WHO_KEY}={WHO}&{NAME_KEY}=Zo%C3%A9"
    first = FakeStudent(url)
    try:
        assert wait_for(lambda: [r.name for r in _roster_rows(app)] == ["Zoé"], 30)
        (row,) = _roster_rows(app)
        assert row.key == f"b:{WHO}" and row.number == 1
    finally:
        first.close()
    again = FakeStudent(url)  # the page reloaded
    other = FakeStudent(app.url.replace("http", "ws"))  # another tab: no key, no name
    try:
        assert wait_for(
            lambda: (
                [(r.name, r.number, r.connected) for r in _roster_rows(app)]
                == [("Zoé", 1, True), ("", 2, True)]
            ),
            30,
        ), _roster_rows(app)
    finally:
        again.close()
        other.close()


@pytest.mark.parametrize(
    "query",
    [
        "sandbox_who=../../etc&sandbox_name=%3Cb%3EZ%C3%A9%3C/b%3E%0A%0A" + "x" * 80,
        "sandbox_who=" + "a" * 25,
        "sandbox_who=0123456789ABCDEF01234567",
        "",
    ],
)
def test_a_crafted_identity_is_refused_or_cleaned(query):
    from sandbox.web.page.link import identity

    key, name = identity(query)
    assert key == ""
    assert "\n" not in name and len(name) <= 40


def test_two_pages_with_one_key_get_two_rows():
    """A tab duplicated with its storage: two pages of one key; the newer keeps the key,
    the other gets its own."""
    from sandbox.web.serving.class_board import Classroom

    class Client:
        def __init__(self, cid):
            self.client_id = cid

    from sandbox.physics.simulation import Simulation

    room = Classroom(lambda cid: True)
    sim = Simulation(get_scene("rotor"))
    for cid in (1, 2):
        room.student(Client(cid), sim, who=WHO)  # type: ignore[arg-type]
    keys = sorted(r.key for r in room.rows())
    assert keys == ["b:" + WHO, "p:1"]


@pytest.mark.browser
# Alone it passes every time; in the full parallel run the reloaded page's name box came
# back first 5 times out of 5 although the browser kept the name. A late handshake whose
# box the page filled itself was one cause (fixed, tested below); another remains (issue
# 38's note): it runs alone, after the parallel run.
@pytest.mark.solo
def test_a_student_keeps_the_name_typed_after_a_reload(open_page, served_class):
    """In a real page: « Votre prénom » comes first while no name is known; typed, then
    the page reloaded, the box reads the name again (last on the page now) and the board
    keeps one row for the student, with that name."""
    app = served_class
    page = open_page(app.url)
    box = page.get_by_role("textbox", name=NAME_LABEL, exact=True)
    box.wait_for(timeout=60_000)
    first = page.get_by_text("Simulation", exact=True).first

    def above() -> bool:  # the name box above the « Simulation » folder
        a, b = box.bounding_box(), first.bounding_box()
        return a is not None and b is not None and a["y"] < b["y"]

    assert above()
    box.fill("Zoé")
    assert wait_for(lambda: [r.name for r in _roster_rows(app)] == ["Zoé"], 30)
    # the page's script kept it (the box named by its row's label, whenever it is typed)
    assert page.evaluate("localStorage.getItem('sandbox-name')") == "Zoé"
    page.reload()
    assert wait_for(lambda: box.count() == 1 and box.input_value() == "Zoé", 60)
    first.wait_for(timeout=60_000)
    # last now (the page still lays out the folders it receives)
    assert wait_for(lambda: not above(), 10), (box.bounding_box(), first.bounding_box())
    assert wait_for(
        lambda: [(r.name, r.number, r.connected) for r in _roster_rows(app)] == [("Zoé", 1, True)],
        30,
    ), _roster_rows(app)


def test_the_teachers_page_shows_rejoindre_until_the_first_student():
    """Students can reach the server (here through --public-url): the teacher's page
    opens on « Rejoindre » (the address and its QR code), and goes back to its usual
    panel when the first student arrives."""
    from sandbox.web.panels.join import FOLDER as JOIN
    from sandbox.web.serving.app import start

    app = start(
        "rotor", port=free_port(), open_message=False, token="tok-2",
        public_url="http://salle-b12.lycee.fr:8080",
    )  # fmt: skip
    teacher = FakeStudent(app.url.replace("http", "ws") + "/prof/tok-2")
    students: list[FakeStudent] = []
    try:
        assert wait_for(lambda: len(app.sessions) == 1, 30)
        (session,) = app.sessions.values()
        view = session.view
        assert wait_for(lambda: view.shown == JOIN, 30), view.shown
        place = view.join.folder.order
        assert place < BOARD_ORDER  # first on the page, not below the controls
        students.append(FakeStudent(app.url.replace("http", "ws")))
        assert wait_for(lambda: view.shown == view.default_folder != JOIN, 30), view.shown
        assert view.join.folder.order > place  # back in its place among the panels
    finally:
        for s in (teacher, *students):
            s.close()
        app.stop()


def test_a_tab_that_comes_back_without_its_name_keeps_it():
    """A tab known by its own key comes back (a reload in a browser that keeps no storage,
    or a worker restarted) before its page sends a name: the board keeps its name; a row
    of a mere connection (no tab key) does not borrow one."""
    roster = Roster(0.0)
    roster.update("w0", [Row(key=f"b:{WHO}", joined=1.0, name="Zoé")], 2.0)
    roster.update("w0", [], 3.0)  # the page reloads...
    roster.update("w1", [Row(key=f"b:{WHO}", joined=4.0, name="")], 5.0)  # ...on worker 1
    roster.update(
        "w1", [Row(key=f"b:{WHO}", joined=4.0, name=""), Row(key="w1:7", joined=6.0)], 7.0
    )
    rows = roster.rows(8.0)
    assert [(r.name, r.number, r.connected) for r in rows] == [("Zoé", 1, True), ("", 2, True)]


def test_a_reload_served_by_the_same_process_finds_the_name_typed(served_class):
    """The name typed reaches the server; the page reloads with its tab key but no name
    (its browser kept none): the process gives the name box the name it last read."""
    from sandbox.web.page.link import WHO_KEY

    app = served_class
    url = app.url.replace("http", "ws") + f"/?{WHO_KEY}={WHO}"
    first = FakeStudent(url, "Zoé")
    try:
        assert wait_for(lambda: [r.name for r in _roster_rows(app)] == ["Zoé"], 30)
    finally:
        first.close()
    again = FakeStudent(url)  # types nothing
    try:
        assert wait_for(lambda: app.classroom.students() == 1 and len(app.sessions) == 1, 30)
        cid = next(iter(app.sessions))  # (the session is listed a moment after the seat)
        assert wait_for(lambda: app.classroom.name_of(cid) == "Zoé", 30)
        assert [(r.name, r.number, r.connected) for r in _roster_rows(app)] == [("Zoé", 1, True)]
    finally:
        again.close()


def test_a_page_whose_identity_arrives_late_gets_its_name_back(gui_server):
    """The handshake of a reloaded page not yet readable when it arrives (a loaded
    machine): the board's next readings ask again, and once the tab's key comes, the empty
    name box gets the name its browser kept and goes last."""
    from sandbox.physics.simulation import Simulation
    from sandbox.web.panels.board import NAME_ORDER

    answers = [("", ""), ("", ""), (WHO, "Zoé")]
    client = SimpleNamespace(client_id=5, gui=gui_server.gui)
    room = Classroom(lambda cid: True)
    room.seat(client, Simulation(get_scene("rotor")), who=lambda: answers.pop(0))  # type: ignore[arg-type]
    assert [r.key for r in room.rows()] == ["p:5"]  # asked again: not yet
    assert [(r.key, r.name) for r in room.rows()] == [(f"b:{WHO}", "Zoé")]
    field = room._students[5].field
    assert field is not None and field.value == "Zoé" and field.order == NAME_ORDER


def test_a_late_identity_moves_the_box_its_page_already_filled_last(gui_server):
    """The full runs' reload failure: the handshake not readable at arrival, the page's
    script fills « Votre prénom » from its storage before the board asks again; the box,
    already named, still goes last once the tab's key comes (it stayed first)."""
    from sandbox.physics.simulation import Simulation
    from sandbox.web.client.fields import set_value
    from sandbox.web.panels.board import NAME_FIRST_ORDER, NAME_ORDER

    answers = [("", ""), (WHO, "Zoé")]
    client = SimpleNamespace(client_id=6, gui=gui_server.gui)
    room = Classroom(lambda cid: True)
    room.seat(client, Simulation(get_scene("rotor")), who=lambda: answers.pop(0))  # type: ignore[arg-type]
    field = room._students[6].field
    assert field is not None and field.order == NAME_FIRST_ORDER
    set_value(field, "Zoé")  # what the page's script typed, from its storage
    assert [(r.key, r.name) for r in room.rows()] == [(f"b:{WHO}", "Zoé")]
    assert field.value == "Zoé" and field.order == NAME_ORDER
