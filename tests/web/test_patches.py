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
