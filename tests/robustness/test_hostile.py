"""The harness of the robustness suites (``hostile.py``): what it measures of a child."""

from __future__ import annotations

from hostile import run_cli


def test_the_peak_memory_is_the_child_s_not_the_test_process_s():
    """A child forked from this process and exec'd kept this process's high-water RSS
    (Linux carries it across exec): after a thousand tests the largest height field
    accepted read 0.5 GB of which sandbox used 0.3. Holding 400 MB here, ``sandbox
    --help`` must read its own few tens of MB."""
    held = bytearray(400 * 2**20)
    held[::4096] = b"\1" * len(held[::4096])  # every page touched: resident
    res = run_cli("--help")
    assert res.code == 0, res.err
    assert res.rss_bytes < 200 * 2**20, f"{res.rss_bytes / 2**20:.0f} MB"
    assert held[4096] == 1
