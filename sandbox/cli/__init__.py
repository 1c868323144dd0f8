"""Command line: ``sandbox list | describe | run | serve | replay`` (bare ``sandbox`` serves).

Every user error prints one line ``sandbox: error: ...`` and exits with code 2; a
diverging simulation exits with code 3 after writing what was computed so far. Any other
exception (a bug) prints one line ``sandbox: error: internal error: <type>: <message> —
please report it (...)`` and exits with code 1; set the environment variable
``SANDBOX_DEBUG=1`` to get the traceback instead. Ctrl-C exits with code 130, quietly.

``sandbox run`` validates everything before simulating: the output file is created (under
a temporary name, renamed at the end) before the first step, and a run is bounded by
:data:`sandbox.runner.MAX_STEPS` steps and :data:`sandbox.runner.MAX_ROWS` rows; MJCF
files are bounded by the limits of :mod:`sandbox.physics.model`.

The package: :mod:`~sandbox.cli.command` (``main``: parse, dispatch, exit code),
:mod:`~sandbox.cli.parser` (the grammar), :mod:`~sandbox.cli.failures` (one line and an
exit code for whatever goes wrong), :mod:`~sandbox.cli.options` (values every command
checks alike), then one module per command: :mod:`~sandbox.cli.describe` (``list`` and
``describe``), :mod:`~sandbox.cli.run`, :mod:`~sandbox.cli.sweep`,
:mod:`~sandbox.cli.serve`, :mod:`~sandbox.cli.replay`, :mod:`~sandbox.cli.bench`.
``python -m sandbox.cli ARGS`` runs the command (:mod:`sandbox.cli.__main__`); the
installed ``sandbox`` script is :func:`sandbox.launch.main`, which imports this package.
"""

from __future__ import annotations

from sandbox.cli.command import main
from sandbox.cli.failures import DEBUG_ENV
from sandbox.cli.options import MAX_WORKERS
from sandbox.cli.parser import build_parser

__all__ = ["DEBUG_ENV", "MAX_WORKERS", "build_parser", "main"]
