"""The ``sandbox`` command: parse the arguments, run the command (``list | describe | run |
sweep | serve | replay | bench``; a bare ``sandbox`` serves), end with its exit code and
one line for any failure (see :mod:`sandbox.cli.failures`).
"""

from __future__ import annotations

import argparse
import os
import sys
from collections.abc import Sequence

from sandbox.cli.bench import cmd_bench
from sandbox.cli.describe import cmd_describe, cmd_list
from sandbox.cli.failures import DEBUG_ENV, held_mujoco_warnings, internal_error
from sandbox.cli.parser import build_parser
from sandbox.cli.replay import cmd_replay
from sandbox.cli.run import cmd_run
from sandbox.cli.serve import cmd_serve
from sandbox.cli.sweep import cmd_sweep
from sandbox.errors import INTERRUPTED, SandboxError, one_line


def main(argv: Sequence[str] | None = None) -> int:
    """Entry point of the ``sandbox`` console script; returns the exit code.

    Outside ``serve``, MuJoCo's warnings (printed by default on stderr, e.g. before a
    divergence) are held back: shown as ``sandbox: warning: MuJoCo: ...`` lines after a
    successful command, dropped after an error, whose one line says what happened.
    """
    argv = list(sys.argv[1:] if argv is None else argv)
    held: list[str] = []
    try:
        args = build_parser().parse_args(argv)
        if args.command in (None, "serve"):
            return cmd_serve(
                getattr(args, "target", None),
                getattr(args, "host", "127.0.0.1"),
                getattr(args, "port", 8080),
                getattr(args, "set", []),
                getattr(args, "workers", None),
                getattr(args, "follow", False),
                getattr(args, "public_url", None),
                getattr(args, "motion", None),
                getattr(args, "max_memory", None),
            )
        with held_mujoco_warnings(held):
            code = _dispatch(args)
    except SandboxError as exc:
        print(f"sandbox: error: {one_line(str(exc))}", file=sys.stderr)
        return exc.exit_code
    except KeyboardInterrupt:
        return INTERRUPTED
    except BrokenPipeError:  # output piped into e.g. `head`
        sys.stderr.close()
        return 0
    except Exception as exc:  # a bug: one line, never a traceback (SANDBOX_DEBUG=1 shows it)
        if os.environ.get(DEBUG_ENV) == "1":
            raise
        return internal_error(exc)
    if code == 0:
        for text in dict.fromkeys(held):
            print(f"sandbox: warning: MuJoCo: {text}", file=sys.stderr)
    return code


def _dispatch(args: argparse.Namespace) -> int:
    if args.command == "list":
        return cmd_list()
    if args.command == "describe":
        return cmd_describe(args.target, args.json, args.max_memory)
    if args.command == "replay":
        return cmd_replay(args)
    if args.command == "bench":
        return cmd_bench(args)
    if args.command == "sweep":
        return cmd_sweep(args)
    return cmd_run(args)
