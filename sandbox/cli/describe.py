"""``sandbox list`` and ``sandbox describe``: the scenes and lessons there are, and what a
scene or an MJCF file declares (parameters, effects, readouts), as text or JSON.
"""

from __future__ import annotations

import json

from sandbox.cli.options import own_source
from sandbox.lessons import lessons
from sandbox.physics.simulation import Simulation
from sandbox.physics.spec import Scene
from sandbox.scenes import DEFAULT_SCENE, SCENES


def cmd_list() -> int:
    """Print the scenes (and lessons) available."""
    found = lessons()
    width = max(len(n) for n in (*SCENES, *found))  # one column for every name
    print("Scenes:")
    for scene in SCENES.values():
        mark = " (default)" if scene.name == DEFAULT_SCENE else ""
        print(f"  {scene.name:<{width}} {scene.title}{mark}")
    print("Lessons (sandbox serve LESSON; lesson:LESSON when a scene has its name; or FILE.md):")
    for name, lesson in found.items():
        print(f"  {name:<{width}} {lesson.title} [{lesson.scene}, {len(lesson.steps)} steps]")
    return 0


def describe(target: str, max_memory: float | None = None) -> dict:
    """JSON-able description of a scene or MJCF file (``max_memory``: ``--max-memory``)."""
    sim = Simulation(own_source(target, max_memory))
    scene = sim.scene if isinstance(sim.scene, Scene) else None
    params = [
        {
            "name": p.name,
            "value": sim.values[p.name],
            "unit": p.unit,
            "min": p.min,
            "max": p.max,
            "doc": p.doc,
            # What the French web page shows (added keys; the ones above are contracts).
            "label": p.label,
            "hint": p.hint,
            "display_unit": p.display_unit,
        }
        for p in (scene.params if scene else ())
    ]
    return {
        "name": sim.label,
        "title": scene.title if scene else sim.label,
        "effects": list(scene.effects.simulated()) if scene else ["file options"],
        "hypotheses": list(scene.effects.hypotheses()) if scene else [],
        "integrator": sim.integrator,
        "timestep": sim.timestep,
        # how the motion is computed: "imposed" (closure equations and inverse dynamics)
        # or "free" (simulated); the ways --motion offers
        "motion": sim.motion,
        "motions": list(sim.motions),
        "params": params,
        "readouts": [
            {
                "name": r.name,
                "unit": r.unit,
                "doc": r.doc,
                "label": r.label,
                "hint": r.hint,
                "display_unit": r.display_unit,
            }
            for r in sim.readout_infos()
        ],
    }


def cmd_describe(target: str, as_json: bool, max_memory: float | None = None) -> int:
    """Print :func:`describe` as JSON or text."""
    info = describe(target, max_memory)
    if as_json:
        print(json.dumps(info, indent=2, ensure_ascii=False))
        return 0
    print(f"{info['name']}: {info['title']}")
    effects = ", ".join(info["effects"])
    numerics = f"{info['integrator']}, dt = {info['timestep']:g} s"
    if info["motion"] == "imposed":
        numerics += " when simulated (--motion free)"
    print(f"  effects: {effects}; {numerics}")
    if len(info["motions"]) > 1:
        other = "free" if info["motion"] == "imposed" else "imposed"
        print(
            f"  motion: {info['motion']} by default (--motion {other}: "
            + (
                "simulated by MuJoCo)"
                if other == "free"
                else "the input's motion imposed, computed exactly by inverse dynamics)"
            )
        )
    if info["params"]:
        print("  parameters:")
        for p in info["params"]:
            print(
                f"    {p['name']:<16} = {p['value']:<8g} {p['display_unit']:<6} "
                f"[{p['min']:g}, {p['max']:g}]  {p['doc']}"
            )
    print("  readouts:")
    for r in info["readouts"]:
        print(f"    {r['name']:<18} [{r['unit']}]  {r['doc']}")
    return 0
