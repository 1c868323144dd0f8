"""``sandbox replay``: a recording served in the browser, re-simulated (``--verify``), or
written out as CSV, a video for slides or a static lesson pack.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from tqdm import tqdm  # type: ignore[import-untyped]  # (viser needs it; no stubs)

from sandbox.cli.options import check_folder, check_port_range
from sandbox.errors import BadOption, shown
from sandbox.recording import Recording, load, write_csv
from sandbox.replay import verify


def _video(rec: Recording, args: argparse.Namespace) -> None:
    """``replay --video``: checked before any frame, a progress bar on a terminal."""
    # viser (a second, 20 MB) only for --video: 'sandbox --help' stays quick and small
    from sandbox.web.video import aliasing
    from sandbox.web.video.options import parse_size
    from sandbox.web.video.render import VideoOptions, check, render_video

    options = VideoOptions(
        args.video,
        size=parse_size(args.size),
        fps=args.fps,
        start=args.start,
        stop=args.stop,
        speed=args.speed,
        plots=tuple(n.strip() for n in str(args.plot).split(",") if n.strip()),
        camera=args.camera,
    )
    check(options, rec)
    hidden = aliasing.of_clip(rec, options)
    if hidden is not None:
        print(f"sandbox: warning: {hidden.english(options.fps)}", file=sys.stderr)
    total = len(options.times(rec))
    with tqdm(total=total, unit="image", disable=not sys.stderr.isatty(), leave=False) as bar:
        frames = render_video(rec, options, lambda done, _: bar.update(done - bar.n))
    seconds = frames / options.fps
    print(f"video written to {args.video}: {frames} frames, {seconds:.1f} s at {options.fps} fps")


def cmd_replay(args: argparse.Namespace) -> int:
    """``sandbox replay``: serve a recording, or verify / export / convert it."""
    files: list[Path] = list(args.file)
    others = args.verify or args.csv is not None or args.video is not None
    if len(files) > 1 and (args.export is None or others):
        raise BadOption("give one recording (several go together only with --export DIR)")
    recs = [load(f, salvage=args.salvage) for f in files]
    for path, one in zip(files, recs, strict=True):
        if not one.complete:
            print(
                f"sandbox: warning: {path} was not closed; replaying its {one.duration:.2f} s",
                file=sys.stderr,
            )
    rec = recs[0]
    offline = (
        args.verify or args.export is not None or args.csv is not None or args.video is not None
    )
    if args.video is not None:
        _video(rec, args)
    if args.csv is not None:
        try:
            usable = not args.csv.is_dir() and args.csv.parent.is_dir()
        except (OSError, ValueError):  # a name too long, a NUL
            usable = False
        if not usable:
            raise BadOption(f"--csv {shown(str(args.csv))}: give a file in an existing folder")
        n = write_csv(rec, args.csv)
        print(f"{n} rows of {len(rec.names)} readouts written to {args.csv}")
    if args.export is not None:
        check_folder(args.export, "--export")
        # viser (a second, 20 MB) only for --export: 'sandbox --help' stays quick and small
        from sandbox.web.replay.pack import export_pack

        index = export_pack(recs, args.export)
        print(
            f"lesson pack written to {index}: {len(recs)} recording(s), each a video with "
            "its plots and lesson steps, and a 3D view (open it in a browser; no Python needed)"
        )
    if args.verify:
        result = verify(rec)
        if result.model.warning:
            print(f"sandbox: warning: {result.model.warning}", file=sys.stderr)
        worst, frames = result.deviation, result.frames
        print(
            f"verify: {frames} frames re-simulated with {result.model.description}, "
            f"maximum deviation {worst:.3g}"
        )
        if worst != 0.0:
            print(
                "sandbox: warning: the re-simulation differs from the recording (another "
                "MuJoCo version or platform?)",
                file=sys.stderr,
            )
    if offline:
        return 0
    # viser (a second, 20 MB) only for a replay served: 'sandbox --help' stays quick and small
    from sandbox.web.replay.player import serve_replay

    check_port_range(args.port)
    serve_replay(rec, host=args.host, port=args.port)
    return 0
