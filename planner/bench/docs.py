"""The README's numbers, made from the current code: ``python -m planner.bench.docs`` rewrites
each generated block of README.md and redraws the pictures they caption; ``--check`` only says
which blocks differ (exit 1), writing nothing.

A generated block sits between ``<!-- generated: NAME -->`` and ``<!-- end generated -->`` lines;
everything else is prose, kept as written. The blocks:

- ``quick-subset``: the tests the quick subset leaves out (tests/slow_tests.txt);
- ``summary-line``: the ``plan`` command's line for junction, seed 1;
- ``parking-picture``, ``junction-picture``, ``tray-picture``: a picture (docs/NAME.png, redrawn;
  its PNG text holds the plan's headline) and its caption, from the seed-1 plan (the tray is
  ``scenes/parts/tray.yaml``, six parts);
- ``mujoco-table``: every shipped scene's seed-1 plan run in MuJoCo on 8 support distributions
  (:mod:`planner.bench.simulate`; about 30 s here, needs the mujoco extra; ``--no-mujoco`` keeps
  the committed table).

Every block comes from seed-1 plans, which a seed decides, and seeded simulations: regenerating
twice changes nothing. tests/planner/bench/test_docs.py fails when a committed block or picture no longer
matches what this makes.
"""

from __future__ import annotations

import argparse
import re
import textwrap
import sys
from collections.abc import Callable
from functools import cache
from pathlib import Path

from ..actions.margins import smallest, with_margins
from ..model.extras import have, needs
from ..model.plan import Plan
from ..model.segments import Transit
from ..model.scene import Scene
from ..model.scene_file import load_scene
from ..queries.session import plan

__all__ = ["BLOCK", "MUJOCO_RUNS", "PICTURES", "README", "blocks", "caption", "mujoco_table", "parts_caption", "quick_subset", "regenerate",
           "seed_one", "summary_line", "table_plans"]

ROOT = Path(__file__).resolve().parents[2]
README = ROOT / "README.md"
SCENES = ROOT / "scenes"
#: A generated block: its name, and its body between the two marker lines.
BLOCK = re.compile(r"<!-- generated: (?P<name>[a-z-]+) -->\n(?P<body>.*?)<!-- end generated -->", re.S)
#: Support distributions per scene in the MuJoCo table.
MUJOCO_RUNS = 8
#: What each picture shows, beyond the numbers (the scene's own story, true of any of its plans).
STORIES = {
    "parking": "the part (blue) is pushed by the pusher (black) into a slot that opens away from it; the orange "
               "line is the path of its centre of friction",
    "junction": "the corridor is too narrow to turn the part round, so one face cannot bring it into the "
                "branch: the part is pushed past the junction, the pusher changes face and pushes it back "
                "into the branch; the orange line is the path of its centre of friction",
}
MOVES = {"plane": "walk round the part", "lift": "lift over the part"}
#: The pictures: scene (under scenes/) and picture name (under docs/).
PICTURES = {"parking": "parking", "junction": "junction", "parts/tray": "tray"}


@cache
def seed_one(name: str) -> tuple[Scene, Plan]:
    """The shipped scene ``name`` and its seed-1 plan (planned once a process)."""
    scene = load_scene(SCENES / f"{name}.yaml")
    return scene, plan(scene, seed=1)


def shipped() -> list[str]:
    """The shipped scenes' names (scenes/*.yaml), in order."""
    return sorted(p.stem for p in SCENES.glob("*.yaml"))


def quick_subset() -> str:
    """The ``quick-subset`` block."""
    listed = [line for line in (ROOT / "tests" / "slow_tests.txt").read_text().splitlines() if line.strip()]
    return (f'`python -m pytest -q -m "not slow"` runs the quick subset: it leaves out the {len(listed)} tests\n'
            "that each took 0.3 s or more (listed in `tests/slow_tests.txt`; `tests/slow_tests.py` says how\n"
            "to regenerate the list).\n")


def summary_line() -> str:
    """The ``summary-line`` block: what ``plan scenes/junction.yaml`` prints, less its times."""
    scene, result = seed_one("junction")
    least = smallest(with_margins(scene, result))
    return f"```text\nsolved: {result.headline()}, smallest margin {least}, planning time ...\n```\n"


def caption(name: str) -> str:
    """The ``NAME-picture`` block: the picture of the seed-1 plan of ``name`` and its caption."""
    _, result = seed_one(name)
    moves = sorted({MOVES[t.mode] for t in result.segments if isinstance(t, Transit)})
    switch = f"; purple, the pusher's {' and '.join(moves)} where it changes edge" if moves else ""
    text = f"*`scenes/{name}.yaml`, seed 1: {result.headline()}. {STORIES[name][0].upper()}{STORIES[name][1:]}{switch}.*"
    return f"![A plan for scenes/{name}.yaml](docs/{name}.png)\n\n{_wrapped(text)}"


def parts_caption(name: str) -> str:
    """The picture of the seed-1 plan of the multi-part scene ``name`` and its caption."""
    _, result = seed_one(name)
    order = ", ".join(dict.fromkeys(m.part for m in result.moves))
    switches = " and its switches of edge" if result.switches else ""
    text = (f"*`scenes/{name}.yaml`, seed 1: {result.headline()}. Each part is drawn in its colour where it "
            f"starts (grey), where its goal is (dashed) and where the plan leaves it (bold), with the path of its "
            f"centre of friction; purple, the pusher's transfers from one part to the next{switches}. The parts go "
            f"in the order {order}.*")
    return f"![A plan for scenes/{name}.yaml](docs/{PICTURES[name]}.png)\n\n{_wrapped(text)}"


def _wrapped(text: str) -> str:
    """``text`` in lines of at most 100 characters, as the README's prose, with its last newline."""
    return textwrap.fill(text, 100, break_long_words=False, break_on_hyphens=False) + "\n"


def table_plans() -> dict[str, str]:
    """Each shipped scene's seed-1 plan in words, as the MuJoCo table's ``plan`` column gives it."""
    return {name: seed_one(name)[1].contents() for name in shipped()}


def mujoco_table() -> str:
    """The ``mujoco-table`` block (needs MuJoCo; minutes)."""
    from ..execution.mujoco_sim import SLIP, simulate
    from .simulate import row

    lines = ["| scene | plan | executed | goal error | path deviation | slip | passed |",
             "|---|---|---|---|---|---|---|"]
    slips = {}
    for name in shipped():
        scene, result = seed_one(name)
        simulation = simulate(scene, result, MUJOCO_RUNS, seed=1) if result.solved else None
        lines.append(row(scene, result, simulation, timing=False))
        if simulation is not None:
            slips[name] = max(r.slip for r in simulation.runs)
    worst = max(slips, key=slips.get)
    lines += ["", _wrapped(f"The worst slip, {slips[worst] * 1e3:.3f} mm on {worst}, is {slips[worst] / SLIP:.0%} "
                           f"of the {SLIP * 1e3:g} mm a run may slip.").rstrip("\n")]
    return "\n".join(lines) + "\n"


def blocks(mujoco: bool = True) -> dict[str, Callable[[], str]]:
    """What makes each block, by name (the MuJoCo table only with ``mujoco``)."""
    made = {"quick-subset": quick_subset, "summary-line": summary_line,
            "parking-picture": lambda: caption("parking"), "junction-picture": lambda: caption("junction"),
            "tray-picture": lambda: parts_caption("parts/tray")}
    return made | ({"mujoco-table": mujoco_table} if mujoco else {})


def regenerate(text: str, made: dict[str, str]) -> str:
    """``text`` with the body of each block named in ``made`` replaced by its new body."""
    return BLOCK.sub(lambda m: m.group(0) if m["name"] not in made else
                     f"<!-- generated: {m['name']} -->\n{made[m['name']]}<!-- end generated -->", text)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m planner.bench.docs", description=__doc__.splitlines()[0])
    p.add_argument("--check", action="store_true", help="only say which blocks differ (exit 1 if any), write nothing")
    p.add_argument("--no-mujoco", action="store_true", help="keep the committed MuJoCo table (no MuJoCo run)")
    args = p.parse_args(argv)
    for module, wanted in (("matplotlib", not args.check), ("mujoco", not args.no_mujoco)):
        if wanted and not have(module):  # one line, before any work
            p.exit(1, f"{p.prog}: error: {needs(module)}{' (or --no-mujoco)' if module == 'mujoco' else ''}\n")
    text = README.read_text()
    found = {m["name"] for m in BLOCK.finditer(text)}
    made = {name: make() for name, make in blocks(not args.no_mujoco).items() if name in found}
    fresh = regenerate(text, made)
    stale = [m["name"] for m in BLOCK.finditer(text) if m["name"] in made and m["body"] != made[m["name"]]]
    if args.check:
        print("stale: " + ", ".join(stale) if stale else "every generated block is current")
        return 1 if stale else 0
    from ..outputs.picture import draw_plan

    for name, picture in PICTURES.items():
        draw_plan(*seed_one(name), str(ROOT / "docs" / f"{picture}.png"))
    if fresh != text:
        README.write_text(fresh)
    print(f"regenerated: {', '.join(made)}; stale before: {', '.join(stale) or 'none'}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
