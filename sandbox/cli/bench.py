"""``sandbox bench``: what accuracy costs in time (integrators × timesteps), the effects
and overhead comparisons, and the sweep, video and classroom benchmarks.
"""

from __future__ import annotations

import argparse
import sys
import tempfile
import time
from pathlib import Path

from sandbox import bench, sweep
from sandbox.cli.options import check_folder
from sandbox.cores import default_workers
from sandbox.errors import BadOption
from sandbox.physics.simulation import Simulation
from sandbox.recording import Recorder, load
from sandbox.scenes import SCENES, get_scene, resolve


def _bench_sweep(target: str) -> int:
    """``sandbox bench --sweep``: the same study in one process, then on every core."""
    study = sweep.bench_study(target)
    cores = default_workers()
    v = study.varies[0]
    print(
        f"{target}: {v.count} runs of {study.duration:g} s, {study.measure.label} over "
        f"{v.name} from {v.start:g} to {v.stop:g}"
    )
    times = {}
    for jobs in dict.fromkeys((1, cores)):
        start = time.perf_counter()
        rows = sweep.run_study(study, jobs)
        times[jobs] = time.perf_counter() - start
        word = "process" if jobs == 1 else "processes"
        print(f"  {jobs} {word:<9} {times[jobs]:6.2f} s  ({len(rows)} rows)")
    if cores > 1:
        ratio = times[1] / times[cores]
        print(
            f"  time in one process / time on {cores}: ×{ratio:.2f}"
            + (" (starting the processes costs more than the runs)" if ratio < 1 else "")
        )
    return 0


def _bench_video(target: str, seconds: float = 30.0) -> int:
    """``sandbox bench --video``: record ``seconds`` of the scene as the page does (a
    frame every 10 ms), then time the video of it at 1280x720 and 30 fps."""
    # viser (a second, 20 MB) only for this benchmark: 'sandbox --help' stays quick and small
    from sandbox.web.video.render import VideoOptions, render_video

    sim = Simulation(resolve(target))
    with tempfile.TemporaryDirectory() as folder:
        path = Path(folder) / "bench.sbx"
        recorder = Recorder(path, sim)
        recorder.frame(sim.readouts())
        while sim.data.time < seconds - 1e-9:
            sim.advance(0.01)
            recorder.frame(sim.readouts())
        recorder.close()
        rec = load(path)
        options = VideoOptions(Path(folder) / "bench.mp4", plots=())
        start = time.perf_counter()
        frames = render_video(rec, options)
        took = time.perf_counter() - start
    length = frames / options.fps
    print(
        f"{target}: {length:.0f} s of video, {frames} frames of 1280x720, made in {took:.1f} s: "
        f"{took / length:.2f} × its length ({took / frames * 1000:.0f} ms a frame)"
    )
    return 0


def cmd_bench(args: argparse.Namespace) -> int:
    """``sandbox bench``: work-precision grid, or the effects / overhead comparisons."""
    if args.classroom is not None:
        # the classroom benchmark's websockets, asyncio and codecs: only for --classroom
        from sandbox.bench.classroom import cli_classroom

        return cli_classroom(args)
    if args.sweep:
        return _bench_sweep(args.scenes[0] if args.scenes else "rotor")
    if args.video:
        return _bench_video(args.scenes[0] if args.scenes else "rotor")
    names = args.scenes or [n for n, s in SCENES.items() if s.accuracy is not None]
    scenes = [get_scene(n) for n in names]
    for scene in scenes:
        if scene.accuracy is None:
            raise BadOption(f"scene {scene.name!r} has no accuracy measure to benchmark")

    def say(line: str) -> None:
        print(line, file=sys.stderr, flush=True)

    if args.effects:
        print(f"{'scene':<18} {'speed ratio':>12} {'error declared':>15} {'error all on':>13}")
        for scene in scenes:
            res = bench.bench_effects(scene, quick=args.quick)
            print(
                f"{scene.name:<18} {res.speed_ratio:>11.2f}x {res.declared.error:>15.2e} "
                f"{res.all_on.error:>13.2e}   drift {res.declared.drift:.1e} -> "
                f"{res.all_on.drift:.1e} ({scene.accuracy.invariant})"  # type: ignore[union-attr]
            )
        print("speed ratio = CPU cost with every effect on / with the scene's effects only")
    if args.overhead:
        print(f"{'scene':<18} {'run / bare':>10} {'x real time':>12}")
        for scene in scenes:
            o = bench.bench_overhead(scene)
            print(f"{scene.name:<18} {o.ratio:>10.2f} {o.realtime_factor:>12.1f}")
        print("goals: run / bare <= 1.25 (readouts at 60 Hz), >= 20x real time at the defaults")
    if args.effects or args.overhead:
        return 0
    check_folder(args.out, "--out")
    start = time.perf_counter()
    results = []
    for scene in scenes:
        say(f"{scene.name}: {scene.accuracy.key} vs the course ...")  # type: ignore[union-attr]
        results.append(bench.bench_scene(scene, quick=args.quick, progress=say))
    if args.merge:
        results = bench.merge_results(results, args.out / "results.json")
    paths = bench.write_results(results, args.out, quick=args.quick)
    print(bench.markdown(results))
    for result in results:
        d = result.default
        if d is not None:
            mark = "on" if d.pareto else "NOT on"
            print(
                f"{result.scene}: default {d.integrator} dt = {d.timestep:g} s, error "
                f"{d.error:.2e}, {mark} the Pareto front"
            )
    print(f"written: {', '.join(str(p) for p in paths)} ({time.perf_counter() - start:.0f} s)")
    return 0
