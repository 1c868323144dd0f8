"""A classroom run in words and as JSON: human-readable lines, measurements then each
target with PASS/FAIL (:func:`report`), and the results as strict JSON (:func:`jsonable`).
"""

from __future__ import annotations

import math
from typing import Any

from sandbox.bench.classroom.wire import BIG_MESSAGE
from sandbox.bench.classroom.workers import worker_lines

STALL = 2.0
"""A browser that waited this long [s] for a frame is a defect to explain: the report then
prints the end of the server's output (warnings, tracebacks) with the figures."""


def report(results: dict[str, Any]) -> str:
    """Human-readable lines: measurements, then each target with PASS/FAIL."""
    m = results["main"]
    fps, rate, delay = m["fps"], m["sim_rate"], m["slider_delay_s"]
    mode = " --follow" if results["follow"] else ""
    mode += " --busy-core" if results.get("busy_core") else ""
    lines = [
        f"classroom: {results['scene']}{mode}, {m['clients']} clients "
        f"({m['connected']} got frames, ready after {m['ready_s']:.1f} s), "
        f"{m['seconds']:g} s measured after {m['warmup_s']:g} s warm-up, {results['date']}"
        + (f"; {m['played']} pressed « Lecture »" if m.get("played") else "")
        + (
            f"; panel {m['panel']!r} picked by {m['panel_picked']}"
            if m.get("panel") is not None
            else ""
        ),
        f"  update frames/s per client   min {fps['min']:.1f}  median {fps['median']:.1f}"
        f"  max {fps['max']:.1f}",
        f"  simulated s per wall s       min {rate['min']:.3f}  median {rate['median']:.3f}"
        f"  ({m['sim_rate_samples']} clients)",
        f"  server CPU                   {m['server_cpu_cores']:.2f} cores "
        f"({m['server_processes']} process(es), clients per process "
        f"{'/'.join(str(n) for n in m['clients_per_process'])}, {m['server_threads']} threads; "
        "busiest " + ", ".join(f"{c:.2f}" for c in m["server_top_thread_cores"][:4]) + ")",
        f"  server CPU per update frame  {m['server_cpu_ms_per_frame']:.2f} ms (all clients' "
        "frames; lower is better, less sensitive to other load than frames/s)",
        *worker_lines(m.get("workers", [])),
        f"  server RSS                   {m['server_rss_bytes'] / 1e6:.0f} MB",
        f"  slider -> first frame        p95 {delay['p95'] * 1000:.0f} ms  median "
        f"{delay['median'] * 1000:.0f} ms  ({m['slider_param']}: {m['slider_samples']} "
        f"shown, {m['slider_not_shown']} not shown)",
        f"  traffic per client           {m['per_client_ws_messages_per_s']:.1f} messages/s, "
        f"{m['per_client_kbytes_per_s']:.1f} kB/s, {m['bytes_per_ws_message']:.0f} B and "
        f"{m['viser_messages_per_ws_message']:.1f} viser messages per websocket message",
        f"  longest wait for a frame     median {m['longest_frame_gap_s']['median']:.2f} s  "
        f"max {m['longest_frame_gap_s']['max']:.2f} s; messages >= {BIG_MESSAGE // 1000} kB: "
        f"{m['big_messages_per_client_per_s']:.2f}/s per client, largest "
        f"{m['largest_message_bytes'] / 1000:.0f} kB",
        f"  bench clients' own CPU       {m['bench_cpu_cores']:.2f} cores",
        f"  machine speed probe          {m.get('machine_probe_ms', math.nan):.2f} ms for a "
        "fixed piece of work, median over the window (lower is faster; the processor's "
        "speed on a small piece of work, whatever the server does)",
        *_teacher_lines(m.get("teacher")),
    ]
    if m["errors"]:
        lines.append(f"  client errors: {'; '.join(m['errors'][:3])}")
    said = results.get("server_output")
    if said:
        lines.append(f"  a browser waited over {STALL:g} s for a frame; the server's last lines:")
        lines += [f"    | {line}" for line in said.strip().splitlines()[-12:]]
    side = m.get("side")
    if isinstance(side, dict) and "ratio_min" in side:
        lines.append(
            f'  a student flooding "Pas"    {side["clicks"]} clicks ({side["refused"]} refused'
            f"): the others' frames/s median {side['fps_before']:.1f} before, "
            f"{side['fps_during']:.1f} during; worst client keeps {side['ratio_min']:.2f}"
            + (f"; flooder error: {side['error']}" if side.get("error") else "")
        )
    if isinstance(side, dict) and "students" in side:
        lines.append(
            f"  {side['students']} more students running {side.get('work', 'studies')}: "
            f"{side['studies_finished']} finished ({side['studies_started']} started); "
            f"the others' slowest frames/s {side['others_fps_min']:.1f}"
            + (f"; errors: {'; '.join(side['errors'][:2])}" if side.get("errors") else "")
        )
    if "drop" in results:
        d = results["drop"]
        series = " ".join(f"{c:.2f}" for c in d["cores_per_s"])
        lines.append(
            f"  after {d['clients']} connect-and-drop ({d['connected']} connected): "
            f"server cores each second {series}"
        )
    o = results["origin"]
    lines.append(
        f"  Origin {o['origin']}: {'refused' if o['refused'] else 'ACCEPTED'} ({o['detail']})"
    )
    lines.append("targets (issues 12 and 20; printed, never asserted):")
    for t in results["targets"]:
        note = ""
        if t["browsers"] is not None and t["browsers"] != m["clients"]:
            note = f"  (target for {t['browsers']} browsers, measured with {m['clients']})"
        if t["target"].endswith("no session"):
            value = "refused" if t["value"] else "accepted"
        elif "fps" in t["key"]:
            value = f"{t['value']:.1f}"
        else:
            value = f"{t['value']:.3f}"
        lines.append(f"  {t['verdict']:<4}  {t['target']:<58} {value}{note}")
    return "\n".join(lines)


def _teacher_lines(teacher: object) -> list[str]:
    """What the teacher's « La classe » said during the run."""
    if not isinstance(teacher, dict):
        return []
    students = teacher.get("students")
    said = (
        f"{students} at 30 frames/s (« Ce portable tient environ {students} élèves »)"
        if students is not None
        else "no estimate shown" + (f" ({teacher['error']})" if teacher.get("error") else "")
    )
    lines = [f"  students this laptop holds   {said}, read on the teacher's board"]
    if teacher.get("lowered_fps") is not None:
        lines.append(f"  frame rate lowered to        {teacher['lowered_fps']} for every student")
    if teacher.get("saturated"):
        lines.append(
            "  saturated                    new students follow the teacher's simulation "
            f"({teacher.get('following', 0)} on the board's last reading)"
        )
    return lines


def jsonable(value: Any) -> Any:
    """``value`` with NaN and infinities as None and tuples as lists (strict JSON)."""
    if isinstance(value, float):
        return value if math.isfinite(value) else None
    if isinstance(value, dict):
        return {k: jsonable(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [jsonable(v) for v in value]
    return value
