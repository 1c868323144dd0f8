"""The merged class board (:class:`Roster`): the rows every source (a worker process)
last reported, the class numbered in order of arrival, a student who left for a while
kept as "parti".
"""

from __future__ import annotations

from collections.abc import Hashable, Sequence
from dataclasses import dataclass, replace

from sandbox.web.loop.capacity import Load, merged
from sandbox.web.panels.board_rows import KEEP_GONE, MAX_ROWS, STALE, TAB_KEY, Board, Row


@dataclass
class _Entry:
    row: Row
    source: Hashable


def _arrival(entry: _Entry) -> tuple[bool, int, float]:
    """Numbered students first, by number; then those not numbered yet."""
    row = entry.row
    return (not row.number, row.number, row.joined)


class Roster:
    """The merged board: the rows every source (a worker process) last reported.

    Students are numbered in order of arrival, once ``settle`` seconds have passed since
    they arrived: by then every source has reported those who arrived before them (two
    workers report at different instants), and a number never changes afterwards. A row
    that a source stops reporting is kept for :data:`KEEP_GONE` seconds, marked gone; a
    source silent for :data:`STALE` seconds (a worker that died) has its students marked
    gone.

    Args:
        start: When the class started (wall clock [s]): ``joined_s`` counts from it.
        keep_gone: Seconds a gone student stays listed.
        stale: Seconds of silence before a source's students count as gone.
        max_rows: Rows held at most.
        settle: Seconds after its arrival before a student is numbered (0: at once, for
            a single source).
    """

    def __init__(
        self,
        start: float,
        *,
        keep_gone: float = KEEP_GONE,
        stale: float = STALE,
        max_rows: int = MAX_ROWS,
        settle: float = 0.0,
    ) -> None:
        self.start = start
        self.settle = settle
        self.keep_gone = keep_gone
        self.stale = stale
        self.max_rows = max_rows
        self._left_out: dict[Hashable, int] = {}  # students not listed, by source
        self._entries: dict[str, _Entry] = {}
        self._heard: dict[Hashable, float] = {}
        self._loads: dict[Hashable, Load] = {}
        self._next = 1

    def update(
        self, source: Hashable, rows: Sequence[Row], now: float, load: Load | None = None
    ) -> None:
        """The rows ``source`` has now (its connected students); those it no longer has
        are marked gone at ``now``. ``load``: what the source's sessions cost (the
        capacity estimate adds every source's)."""
        self._heard[source] = now
        if load is not None:
            self._loads[source] = load
        seen = set()
        for row in sorted(rows, key=lambda r: (r.joined, r.key)):
            seen.add(row.key)
            entry = self._entries.get(row.key)
            if entry is not None:
                # a tab known by its own key (after a reload or a restart) keeps its name
                # until its page sends one
                name = row.name or (entry.row.name if row.key.startswith(TAB_KEY) else "")
                entry.row = replace(row, number=entry.row.number, left=0.0, name=name)
                entry.source = source
                continue
            if len(self._entries) >= self.max_rows:
                self._forget_oldest_gone()
            if len(self._entries) >= self.max_rows:
                continue
            self._entries[row.key] = _Entry(replace(row, number=0, left=0.0), source)
        for key, entry in self._entries.items():
            if entry.source == source and key not in seen and entry.row.connected:
                entry.row = replace(entry.row, left=now)
        self._left_out[source] = sum(1 for r in rows if r.key not in self._entries)

    @property
    def left_out(self) -> int:
        """Connected students not listed: the board is full."""
        return sum(self._left_out.values())

    def drop(self, source: Hashable, now: float) -> None:
        """``source`` is gone (a worker restarted): its students count as gone."""
        self._heard.pop(source, None)
        self._left_out.pop(source, None)
        self._loads.pop(source, None)
        for entry in self._entries.values():
            if entry.source == source and entry.row.connected:
                entry.row = replace(entry.row, left=now)

    def _forget_oldest_gone(self) -> None:
        gone = [(e.row.left, k) for k, e in self._entries.items() if not e.row.connected]
        if gone:
            del self._entries[min(gone)[1]]

    def rows(self, now: float) -> list[Row]:
        """Every row (gone ones included, until :data:`KEEP_GONE` passes), in order of
        arrival."""
        for source, heard in list(self._heard.items()):
            if now - heard > self.stale:
                self.drop(source, now)
        for key in [
            k for k, e in self._entries.items() if e.row.left and now - e.row.left > self.keep_gone
        ]:
            del self._entries[key]
        settled = [e for e in self._entries.values() if not e.row.number]
        for entry in sorted(settled, key=lambda e: (e.row.joined, e.row.key)):
            if entry.row.joined > now - self.settle:
                break
            entry.row = replace(entry.row, number=self._next)
            self._next += 1
        return [e.row for e in sorted(self._entries.values(), key=_arrival)]

    def board(self, now: float) -> Board:
        """The merged board at ``now``."""
        rows = tuple(self.rows(now))
        load = merged(self._loads.values()) if self._loads else None
        return Board(self.start, rows, self.left_out, load=load)
