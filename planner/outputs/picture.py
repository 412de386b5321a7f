"""A still picture of a plan (PNG, matplotlib): ``python -m planner.outputs.picture SCENE --out FILE``.

Draws the workspace, the obstacles, the part and its pusher at the start of every push and at
the end, faint copies along the way, and the path of the centre of friction; for each switch of
edge, the path of the pusher's face centre round the part (dashed where it is lifted over it) and
faint outlines of the pusher along it. The rerun recording is the full, animated view; this is
for documents.
"""

from __future__ import annotations

import argparse
import sys

import numpy as np

from mechanics import exp_twist, transform_points

from ..model.bodies import pusher_frame_body, pusher_polygon
from ..model.extras import have, needs, pyplot
from ..model.scene import Scene
from ..model.plan import Plan
from ..model.segments import Transit
from ..model.scene_file import load_scene
from ..queries.session import plan
from ..actions.transit import transit_pieces, transit_poses

__all__ = ["TRANSIT", "draw_parts_plan", "draw_plan", "main"]

#: Colour of the pusher's moves between edges, apart from the part's blue and the CF path's orange.
TRANSIT = "#8e44ad"


def draw_plan(scene: Scene, result: Plan, path: str, copies_per_metre: float = 40.0) -> None:
    """Write a PNG of ``result`` for ``scene`` to ``path``, with ``copies_per_metre`` faint
    copies of the moving body per metre it travels, and the plan's :meth:`~planner.model.plan.Plan.headline`
    as its ``Description`` text."""
    plt = pyplot()  # first: without matplotlib, one line naming the extra

    xmin, ymin, xmax, ymax = scene.workspace
    fig, ax = plt.subplots(figsize=(6, 6 * (ymax - ymin) / (xmax - xmin)), dpi=110)
    ax.add_patch(plt.Rectangle((xmin, ymin), xmax - xmin, ymax - ymin, fill=False, lw=1.5, color="0.3"))
    for obstacle in scene.obstacles:
        ax.fill(*obstacle.exterior.xy, color="#c8504b", alpha=0.85, lw=0)
    outline = np.vstack([scene.slider.vertices, scene.slider.vertices[:1]])

    def draw_part(pose, edge, alpha, lw):
        ax.plot(*transform_points(outline, pose).T, color="#2a6fb0", alpha=alpha, lw=lw)
        if edge is not None:
            pusher = np.asarray(pusher_polygon(scene.slider, edge, scene.pusher.width, scene.pusher.depth).exterior.coords)
            ax.fill(*transform_points(pusher, pose).T, color="#333333", alpha=alpha, lw=0)

    def draw_transit(transit: Transit):
        # Fewer copies than along a push: the pusher is small, and copies of it turning round the
        # part would hide the path they follow.
        body = pusher_frame_body(scene.pusher.width, scene.pusher.depth)
        for xy, airborne in transit_pieces(transit):
            ax.plot(*xy.T, "--" if airborne else "-", color=TRANSIT, lw=1.2, zorder=3)
        times = np.linspace(0.0, transit.duration, max(3, int(transit.duration * copies_per_metre / 2) + 1))
        poses, lifted = transit_poses(transit, body, times)
        for q, airborne in zip(poses, lifted):
            ax.plot(*transform_points(np.vstack([body, body[:1]]), q).T, "--" if airborne else "-",
                    color=TRANSIT, alpha=0.5, lw=0.8, zorder=3)

    ax.plot(*transform_points(outline, scene.goal).T, "--", color="#3a9a4a", lw=1.5)
    cf_path = [transform_points(scene.slider.cf[None], scene.start)[0]]
    for seg in result.segments:
        if seg.kind == "transit":  # the part stands still: only the pusher moves
            draw_transit(seg)
            continue
        length = seg.duration  # unit-speed twists: duration bounds the distance travelled
        times = np.linspace(0.0, seg.duration, max(2, int(length * copies_per_metre) + 1))
        poses = exp_twist(seg.start, seg.twist, times)
        for q in poses[1:-1]:
            draw_part(q, None, 0.25, 0.8)
        draw_part(seg.start, seg.edge, 1.0, 1.5)
        fine = exp_twist(seg.start, seg.twist, np.linspace(0.0, seg.duration, 100))
        cf_path += [transform_points(scene.slider.cf[None], q)[0] for q in fine]
    draw_part(result.final, result.segments[-1].edge if result.segments else None, 1.0, 1.5)
    ax.plot(*np.array(cf_path).T, color="#e08a1e", lw=1.2)
    ax.set_xlim(xmin, xmax), ax.set_ylim(ymin, ymax)
    ax.set_aspect("equal")
    ax.set_title(f"{scene.name}: {result.contents()}" if result.solved
                 else f"{scene.name}: not solved")
    fig.tight_layout()
    # The plan's numbers in the file itself (a PNG text chunk): a document's caption can be checked
    # against the picture without comparing pixels (planner.bench.docs).
    fig.savefig(path, metadata={"Description": f"{scene.name}: {result.headline() if result.solved else 'not solved'}"})
    plt.close(fig)


def draw_parts_plan(scene: Scene, result: Plan, path: str) -> None:
    """Write a PNG of the multi-part plan ``result`` for ``scene`` to ``path``: each part in its
    colour (the recording's, :func:`~planner.outputs.parts_recording.part_colours`) at its start
    (thin, grey) and where the plan leaves it (bold), its goal dashed, the path of its centre of
    friction over all its moves, and the pusher's transfers between parts in purple (dashed where
    lifted); the plan's headline as the PNG's ``Description`` text."""
    plt = pyplot()
    from .parts_recording import part_colours  # rerun: only when drawing several parts

    xmin, ymin, xmax, ymax = scene.workspace
    fig, ax = plt.subplots(figsize=(7, 7 * (ymax - ymin) / (xmax - xmin)), dpi=110)
    ax.add_patch(plt.Rectangle((xmin, ymin), xmax - xmin, ymax - ymin, fill=False, lw=1.5, color="0.3"))
    for obstacle in scene.obstacles:
        ax.fill(*obstacle.exterior.xy, color="#c8504b", alpha=0.85, lw=0)
    colours = {n: "#%02x%02x%02x" % tuple(c) for n, c in part_colours(scene).items()}
    finals = result.finals
    for part in scene.parts:
        outline = np.vstack([part.slider.vertices, part.slider.vertices[:1]])
        ax.plot(*transform_points(outline, part.start).T, color="0.55", lw=0.8)
        ax.plot(*transform_points(outline, part.goal).T, "--", color=colours[part.name], lw=1.0)
        ax.plot(*transform_points(outline, finals[part.name]).T, color=colours[part.name], lw=2.0)
        x, y = transform_points(part.slider.cf[None], finals[part.name])[0]
        ax.annotate(part.name, (x, y), ha="center", va="center", fontsize=7, color=colours[part.name])
    for move in result.moves:
        cf = scene.part(move.part).slider.cf[None]
        trail = [transform_points(cf, s.start)[0] for s in move.segments[:1]]
        for s in move.segments:
            if s.kind == "push":
                trail += [transform_points(cf, q)[0] for q in exp_twist(s.start, s.twist, np.linspace(0, s.duration, 60))]
        ax.plot(*np.array(trail).T, color=colours[move.part], lw=1.0, alpha=0.8)
        if move.transfer is not None:
            for xy, airborne in transit_pieces(move.transfer):
                ax.plot(*xy.T, ":" if airborne else "-", color=TRANSIT, lw=0.9, alpha=0.8, zorder=3)
    ax.set_xlim(xmin, xmax), ax.set_ylim(ymin, ymax)
    ax.set_aspect("equal")
    ax.set_title(f"{scene.name}: {result.contents()}" if result.solved else f"{scene.name}: not solved")
    fig.tight_layout()
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
    (draw_parts_plan if len(scene.parts) > 1 else draw_plan)(scene, plan(scene, seed=args.seed), args.out)
    return 0


if __name__ == "__main__":
    sys.exit(main())
