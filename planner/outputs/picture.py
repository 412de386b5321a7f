"""A still picture of a plan (PNG, matplotlib): ``python -m planner.outputs.picture SCENE --out FILE``.

A plan of any number of parts: draws the workspace, the obstacles, and each part where it
starts (thin, grey), its goal (dashed), where the plan leaves it (bold, with the pusher on the
last part pushed) and the path of its centre of friction; for each switch of edge and each
transfer between parts, the path of the pusher's face centre (dashed where it is lifted). Along
the way, unless asked for none (the default for several parts, whose copies would hide one
another): the part and its pusher at the start of every push (bold), faint copies of the part
along each push and of the pusher along each path between contacts. The one part of a
``slider:`` scene is blue, its goal green and its path orange; the parts of a ``parts:`` scene
each take their colour (:mod:`planner.outputs.looks`, as in the recording) and carry their
names. The rerun recording is the full, animated view; this is for documents.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from mechanics import exp_twist, transform_points

from ..model.bodies import pusher_frame_body, pusher_polygon
from ..model.extras import have, needs, pyplot
from ..model.plan import Plan
from ..model.scene import Part, Scene
from ..model.scene_file import load_scene
from ..model.segments import Push, Transfer, Transit
from ..queries.session import plan
from ..actions.transit import transit_pieces, transit_poses
from .looks import hex_colour, looks

__all__ = ["TRANSIT", "draw_plan", "main"]

#: Colour of the pusher's moves between edges and between parts, apart from the parts' colours.
TRANSIT = "#8e44ad"
#: The one part of a slider: scene (blue), its goal (green) and its CF's path (orange).
_SINGLE = ((42, 111, 176), (58, 154, 74), (224, 138, 30))


def draw_plan(scene: Scene, result: Plan, path: str, copies_per_metre: float | None = None) -> None:
    """Write a PNG of ``result`` for ``scene`` (module docstring) to ``path``, with
    ``copies_per_metre`` faint copies of the moving body per metre it travels (default: 40 for a
    scene of one part, 0 for several; 0 draws no outline along the way), and the plan's
    :meth:`~planner.model.plan.Plan.headline` as its ``Description`` text."""
    plt = pyplot()  # first: without matplotlib, one line naming the extra
    if copies_per_metre is None:
        copies_per_metre = 40.0 if len(scene.parts) == 1 else 0.0
    along = copies_per_metre > 0

    xmin, ymin, xmax, ymax = scene.workspace
    fig, ax = plt.subplots(figsize=(6, 6 * (ymax - ymin) / (xmax - xmin)), dpi=110)
    ax.add_patch(plt.Rectangle((xmin, ymin), xmax - xmin, ymax - ymin, fill=False, lw=1.5, color="0.3"))
    for obstacle in scene.obstacles:
        ax.fill(*obstacle.exterior.xy, color="#c8504b", alpha=0.85, lw=0)
    look = looks(scene, _SINGLE)
    body = pusher_frame_body(scene.pusher.width, scene.pusher.depth)

    def outline(part: Part) -> np.ndarray:
        return np.vstack([part.slider.vertices, part.slider.vertices[:1]])

    def draw_part(part: Part, pose, edge, alpha, lw):
        ax.plot(*transform_points(outline(part), pose).T, color=hex_colour(look[part.name].part), alpha=alpha, lw=lw)
        if edge is not None:
            pusher = np.asarray(pusher_polygon(part.slider, edge, scene.pusher.width, scene.pusher.depth).exterior.coords)
            ax.fill(*transform_points(pusher, pose).T, color="#333333", alpha=alpha, lw=0)

    def draw_transit(move: Transit | Transfer):
        for xy, airborne in transit_pieces(move):
            ax.plot(*xy.T, "--" if airborne else "-", color=TRANSIT, lw=1.2, zorder=3)
        if not along:
            return
        # Fewer copies than along a push: the pusher is small, and copies of it turning round the
        # part would hide the path they follow.
        times = np.linspace(0.0, move.duration, max(3, int(move.duration * copies_per_metre / 2) + 1))
        poses, lifted = transit_poses(move, body, times)
        for q, airborne in zip(poses, lifted):
            ax.plot(*transform_points(np.vstack([body, body[:1]]), q).T, "--" if airborne else "-",
                    color=TRANSIT, alpha=0.5, lw=0.8, zorder=3)

    for part in scene.parts:
        ax.plot(*transform_points(outline(part), part.start).T, color="0.55", lw=0.8)
        ax.plot(*transform_points(outline(part), part.goal).T, "--", color=hex_colour(look[part.name].goal), lw=1.5)
    cf_paths = {p.name: [transform_points(p.slider.cf[None], p.start)[0]] for p in scene.parts}
    for name, seg in result.steps:
        if not isinstance(seg, Push):  # a transit or a transfer: the parts stand still, only the pusher moves
            draw_transit(seg)
            continue
        part = scene.part(name)
        length = seg.duration  # unit-speed twists: duration bounds the distance travelled
        times = np.linspace(0.0, seg.duration, max(2, int(length * copies_per_metre) + 1))
        poses = exp_twist(seg.start, seg.twist, times)
        for q in poses[1:-1]:
            draw_part(part, q, None, 0.25, 0.8)
        if along:
            draw_part(part, seg.start, seg.edge, 1.0, 1.5)
        fine = exp_twist(seg.start, seg.twist, np.linspace(0.0, seg.duration, 100))
        cf_paths[name] += [transform_points(part.slider.cf[None], q)[0] for q in fine]
    pushing = {name: s.edge for name, s in result.steps[-1:]}  # the pusher where the last step leaves it
    for name, pose in result.finals.items():
        part = scene.part(name)
        draw_part(part, pose, pushing.get(name), 1.0, 1.5)
        ax.plot(*np.array(cf_paths[name]).T, color=hex_colour(look[name].path), lw=1.2)
        if look[name].name is not None:
            ax.annotate(name, tuple(transform_points(part.slider.cf[None], pose)[0]), ha="center", va="center",
                        fontsize=7, color=hex_colour(look[name].part))
    ax.set_xlim(xmin, xmax), ax.set_ylim(ymin, ymax)
    ax.set_aspect("equal")
    ax.set_title(f"{scene.name}: {result.contents()}" if result.solved
                 else f"{scene.name}: not solved")
    fig.tight_layout()
    # The plan's numbers in the file itself (a PNG text chunk): a document's caption can be checked
    # against the picture without comparing pixels (planner.bench.docs).
    fig.savefig(path, metadata={"Description": f"{scene.name}: {result.headline() if result.solved else 'not solved'}"})
    plt.close(fig)


def main(argv: list[str] | None = None) -> int:
    p = argparse.ArgumentParser(prog="python -m planner.outputs.picture", description=__doc__.splitlines()[0])
    p.add_argument("scene")
    p.add_argument("--out", required=True, help="PNG file to write")
    p.add_argument("--seed", type=int, default=None)
    args = p.parse_args(argv)
    if not have("matplotlib"):  # before the planning, one line
        sys.exit(f"{p.prog}: error: {needs('matplotlib')}")
    scene = load_scene(args.scene)
    draw_plan(scene, plan(scene, seed=args.seed), args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
