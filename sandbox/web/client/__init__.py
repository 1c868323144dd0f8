"""What every page is built from, lowest in the web layer: text made safe to show (escaping,
French numbers), the French controls (:mod:`.fields`), matplotlib's one chart thread, and
the project's few uses of viser's internals (upload cap, pose messages straight to the
queue, loop-bound wake-ups), each checked against the viser installed (:mod:`.patches`).
"""
