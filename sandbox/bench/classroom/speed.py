"""How fast the machine itself ran during a classroom benchmark.

A laptop or a virtual machine does not run at one speed: on the machine the project is
measured on, the same classroom run gave the heavy top 48.7 then 27.5 frames/s a quarter
of an hour apart, and a fixed piece of work took 24 ms, then 35 ms for several seconds.
Comparing a run with a saved one (``--compare``) then mixes a code change with the
machine's mood. :class:`SpeedProbe` times a small fixed piece of work (MuJoCo steps and
Python arithmetic, the server's own mix) once every half second *during* the measured
window, in CPU time of its own thread (the load of the server on the other threads does
not count, a slower processor does), and the comparison reads CPU per frame at the saved
run's machine speed.
"""

from __future__ import annotations

import statistics
import threading
import time

import mujoco

PERIOD = 0.5
"""Seconds between two timings (one costs ~6 ms with its warm-up: 1 % of a core)."""

_MODEL = """
<mujoco>
  <option timestep="0.001" integrator="RK4"/>
  <worldbody>
    <body><joint type="hinge" axis="0 0 1"/><geom type="capsule" size="0.02 0.1"/>
      <body pos="0.2 0 0"><joint type="hinge" axis="0 1 0"/>
        <geom type="box" size="0.05 0.02 0.02"/></body>
    </body>
  </worldbody>
</mujoco>
"""


class SpeedProbe:
    """Times the same work again and again in a thread of its own, until stopped."""

    def __init__(self, period: float = PERIOD) -> None:
        self.period = period
        self.model = mujoco.MjModel.from_xml_string(_MODEL)
        self.data = mujoco.MjData(self.model)
        self.times: list[float] = []
        self._stop = threading.Event()
        self._thread: threading.Thread | None = None

    def work(self) -> float:
        """One timing: CPU seconds of this thread for the fixed work."""
        mujoco.mj_resetData(self.model, self.data)
        self.data.qvel[:] = (3.0, 1.0)
        start = time.thread_time()
        mujoco.mj_step(self.model, self.data, 300)
        total = 0
        for k in range(20_000):
            total += k * k
        return time.thread_time() - start

    def start(self) -> None:
        """Start timing (a daemon thread)."""
        self._stop.clear()
        self._thread = threading.Thread(target=self._run, name="speed-probe", daemon=True)
        self._thread.start()

    @property
    def running(self) -> bool:
        """True while it times its work (between :meth:`start` and :meth:`stop`)."""
        return self._thread is not None and self._thread.is_alive()

    def stop(self) -> float:
        """Stop, and return the median timing [ms] (NaN without any)."""
        self._stop.set()
        if self._thread is not None:
            self._thread.join(5.0)
        return statistics.median(self.times) * 1000.0 if self.times else float("nan")

    def _run(self) -> None:
        while not self._stop.is_set():
            self.work()  # warms the caches the half-second's sleep let go cold
            self.times.append(self.work())
            self._stop.wait(self.period)
