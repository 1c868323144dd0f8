"""The ``sandbox`` command as installed: :func:`sandbox.cli.main`, imported only here.

Importing the CLI loads MuJoCo, numpy and viser (about half a second). A Ctrl-C in that
half second would print a KeyboardInterrupt traceback through the imports; here it ends
the command quietly with the shell's code for an interrupt (130), as a Ctrl-C later does.
"""

from __future__ import annotations

import sys
from collections.abc import Sequence

from sandbox.errors import INTERRUPTED


def main(argv: Sequence[str] | None = None) -> int:
    """Run the CLI; a Ctrl-C while it loads ends it with :data:`INTERRUPTED`."""
    try:
        # inside the guard, not at module level: a Ctrl-C while MuJoCo and numpy load ends here
        from sandbox.cli import main as cli_main
    except KeyboardInterrupt:
        print("sandbox: interrupted", file=sys.stderr)
        return INTERRUPTED
    return cli_main(argv)


if __name__ == "__main__":
    sys.exit(main())
