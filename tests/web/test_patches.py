"""The shared check of viser's internals before the project changes its server."""

from __future__ import annotations


def test_a_viser_without_the_internals_is_left_as_it_is_with_one_warning(caplog):
    from sandbox.web.patches import internals_present

    def missing() -> bool:
        raise ImportError("no such module")

    assert internals_present(lambda: True, "unused")
    assert not internals_present(lambda: False, "events stay as they are")
    assert not internals_present(missing, "uploads are not capped")
    assert [r.getMessage() for r in caplog.records] == [
        "events stay as they are",
        "uploads are not capped",
    ]
