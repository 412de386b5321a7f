"""Speed of the simulator: ``python -m mechanics.quasistatic``.

A 10 x 6 cm block on a grid of about 100 support points, pushed 20 cm at 5 cm/s (``DEFAULT_STEPS``
steps) by a flat pusher on its long edge (two-point line contact, mu = 0.5):

* stable pushes (a translation along the normal and a turn about a far COR): the slider moves
  with the pusher, so :func:`.simulate_push` solves the contact problem once;
* one step (every contact mode solved), for the line contact and for a point finger: what a push
  pays per step while anything slips.
"""

from __future__ import annotations

import time

import numpy as np
import shapely

from ..twist import cor_to_twist
from . import Contact, grid_support, simulate_push, solve_step

BLOCK = shapely.box(-0.05, 0.0, 0.05, 0.06)
LINE = [Contact([-0.05, 0.0], [0.0, 1.0], 0.5), Contact([0.05, 0.0], [0.0, 1.0], 0.5)]
FINGER = [Contact([0.02, 0.0], [0.0, 1.0], 0.3)]
SPEED, LENGTH = 0.05, 0.20


def _rate(run, seconds: float = 2.0) -> float:
    """Calls of ``run`` per second, measured for about ``seconds``."""
    count, start = 0, time.perf_counter()
    while time.perf_counter() - start < seconds:
        run()
        count += 1
    return count / (time.perf_counter() - start)


def main() -> None:
    support = grid_support(BLOCK, 100)
    cor = np.array([-0.5, 0.03])  # far to the left of the block, level with its CF: a stable turn
    turn = cor_to_twist(cor, 1) * SPEED / np.linalg.norm(cor - support.centre)
    print(f"block 10 x 6 cm, {len(support.points)} support points, push {LENGTH * 100:.0f} cm")
    for name, twist in [("straight", [0.0, SPEED, 0.0]), ("turning", turn)]:
        push = simulate_push(support, LINE, twist, LENGTH / SPEED, footprint=BLOCK)
        assert push.sticks
        rate = _rate(lambda: simulate_push(support, LINE, twist, LENGTH / SPEED, footprint=BLOCK))
        print(f"stable {name} line push, {push.steps} steps: {rate:.0f} pushes/s")
    for name, contacts in [("line contact", LINE), ("point finger", FINGER)]:
        rate = _rate(lambda: solve_step(support, contacts, [0.01, SPEED, 0.0]))
        print(f"one step, {name}: {rate:.0f} steps/s")


if __name__ == "__main__":
    main()
