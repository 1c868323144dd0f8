"""Files the package writes are UTF-8 whatever the locale (Windows' default is cp1252, which
has no "≥" or "→"; the C locale's is ASCII)."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

WRITER = r"""
import locale
import sys
from pathlib import Path
from types import SimpleNamespace

encoding = locale.getpreferredencoding(False)
print(encoding)
out = Path(sys.argv[1])

import sandbox.bench.plot
from sandbox import bench
from sandbox.recording import Recorder, load, write_csv
from sandbox.web.replay.export import export_static

sandbox.bench.plot.plot_scene = lambda res, path: path  # no PNG: the text files are tested
run = bench.Run("rotor", "euler", 1e-3, 1.0, error=0.01, drift=0.0, default=True)
cost = bench.SessionCost("rotor", "euler", 1e-3, 1e-4, 1e-5, 1e-5)
result = bench.SceneResult("rotor", "ω", "énergie", "euler", 1e-3, [run], session=cost)
bench.write_results([result], out / "bench", quick=True)

# a readout named in French (a file's own names may be), through the CSV writer
write_csv(SimpleNamespace(names=["énergie_J", "θ̇"], readouts=[[1.5, 2.0]]), out / "r.csv")

from sandbox.physics.simulation import Simulation
from sandbox.scenes import get_scene

sim = Simulation(get_scene("rotor"))
recorder = Recorder(out / "lesson.sbx", sim)
for _ in range(3):
    sim.step(10)
    recorder.frame(sim.readouts())
recorder.close()
export_static(load(out / "lesson.sbx"), out / "export")
"""


def narrow_locale_env() -> dict[str, str]:
    """This environment with an ASCII locale and Python's UTF-8 mode off."""
    env = {k: v for k, v in os.environ.items() if not k.startswith(("LC_", "PYTHONIO"))}
    env.update(PYTHONUTF8="0", LC_ALL="C", LANG="C")
    return env


def test_files_written_under_an_ascii_locale_are_utf8(tmp_path: Path) -> None:
    done = subprocess.run(
        # the command line is ASCII too: non-ASCII letters as escapes in string literals
        [sys.executable, "-c", WRITER.encode("ascii", "backslashreplace").decode(), str(tmp_path)],
        env=narrow_locale_env(),
        cwd=tmp_path,
        capture_output=True,
        text=True,
        encoding="utf-8",
        timeout=180,
    )
    assert done.returncode == 0, done.stderr[-3000:]
    encoding = done.stdout.splitlines()[0]
    assert "utf" not in encoding.lower().replace("-", ""), encoding  # e.g. ANSI_X3.4-1968

    md = (tmp_path / "bench" / "results.md").read_text(encoding="utf-8")
    assert "goal ≥ " in md and "### rotor — key: `ω`, invariant: énergie" in md
    assert "rotor,euler" in (tmp_path / "bench" / "results.csv").read_text(encoding="utf-8")
    assert '"rotor"' in (tmp_path / "bench" / "results.json").read_text(encoding="utf-8")
    csv = (tmp_path / "r.csv").read_text(encoding="utf-8")
    assert csv.splitlines() == ["énergie_J,θ̇", "1.5,2"]
    html = (tmp_path / "export" / "index.html").read_text(encoding="utf-8")
    assert "var fr = {" in html  # the French page (its words JSON-escaped: ASCII today)
    assert (tmp_path / "export" / "readouts.csv").read_text(encoding="utf-8").startswith("time")
