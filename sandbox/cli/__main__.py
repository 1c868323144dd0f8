"""``python -m sandbox.cli ARGS``: the ``sandbox`` command without the installed script
(the classroom benchmark and the tests start their servers so)."""

from __future__ import annotations

import sys

from sandbox.cli.command import main

if __name__ == "__main__":
    sys.exit(main())
