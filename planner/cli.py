"""The ``plan`` command: parse the flags, run the pipeline (:func:`planner.pipeline.run`), print
what it found and exit with its code. Several scenes, or ``--seeds``, make a batch instead
(:mod:`planner.batch.command`).

What each flag asks is the pipeline's option of the same name (:class:`planner.pipeline.RunOptions`;
``--plan`` is ``plan_file``, the ``--sim-...`` angles are in degrees here, radians there); the
planner's own flags change the options the scene file asks for (its ``planner:`` block and
``pusher.transit``), resolved once into the run's planner options. Errors the library names by an
option's field are printed with the flag (:mod:`planner.flags`).

Exit codes: 0 solved (and verified, if asked), 1 bad input (one line naming the field), 2 not
solved or certified unreachable (one line saying why; nothing is verified), 3 verified and some
push slipped beyond the tolerance, or a simulated run missed the goal, slipped or collided, 4 an
output could not be written (one line naming the file), 130 Ctrl-C and 143 SIGTERM
(:mod:`planner.model.stop`). :func:`read_inputs` checks everything a run reads before anything is
computed or written.

Importing this module changes nothing: :func:`main` sets the process up (one BLAS thread, its
signal handlers) before it loads the planner.
"""

from __future__ import annotations

import argparse
import atexit
import math
import os
import signal
import sys
import threading
import time
from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, NamedTuple

from .flags import flag_of, options_of, parser

if TYPE_CHECKING:
    from .model.margin import Margin
    from .model.options import PlannerOptions
    from .model.scene import Scene
    from .pipeline import RunOptions

__all__ = ["Inputs", "main", "read_inputs"]

def _stop_while_loading(signum: int, frame) -> None:
    # Ctrl-C or SIGTERM while the planner loads: nothing runs or is written yet, so the command
    # ends at once with the one line main() would print, not an import's traceback.
    os.write(2, b"plan: interrupted\n" if signum == signal.SIGINT else b"plan: terminated\n")
    os._exit(128 + signum)


def _silence_nanobind_leak_report() -> None:
    # nanobind reports OMPL objects still alive at interpreter exit on stderr; harmless noise
    # (docs/stack.md, "Leak report at exit"). Runs before finalisation, after everything of ours is flushed.
    sys.stdout.flush()
    sys.stderr.flush()
    os.dup2(os.open(os.devnull, os.O_WRONLY), 2)


class Inputs(NamedTuple):
    """A command line, checked: the scene as its file gives it, the run's options and the
    planner's (the scene's own with the planner flags applied): :func:`planner.pipeline.run`'s
    arguments."""

    scene: Scene
    options: RunOptions
    planner_options: PlannerOptions


def read_inputs(argv: Sequence[str] | None = None) -> Inputs:
    """Parse and check the command line ``argv`` and read the scene it names, computing and
    writing nothing: every bad input is found here, before any planning (a plan file is read
    and fitted to the scene by the run, before anything else).

    Raises
    ------
    SceneError
        Naming the flag or field at fault.
    SystemExit
        On argparse's usage errors (code 2) and ``--help`` (code 0).
    """
    from .model.fields import FileFieldError, SceneError
    from .model.scene_file import load_scene
    from .pipeline import RunOptions

    args = parser().parse_args(argv)
    for flag, value in (("--engine", args.engine), ("--jobs", args.jobs), ("--address", args.address)):
        if value is not None and args.reach is None:
            raise SceneError(flag, "is for a batch (several scenes or --seeds) or a --reach map")
    if _is_batch(args) or args.resume:
        raise SceneError("--resume" if args.resume else "scene", "several scenes, --seeds or --resume make a batch, "
                                                               "which the plan command runs itself (planner.batch)")
    try:
        scene = load_scene(args.scene[0])
    except SceneError as err:
        raise FileFieldError(err.field, err.problem) from None
    planner_options = options_of(args, scene.options)
    out = Path(args.out) if args.out else _fresh_folder(Path("logs") / f"{scene.name}-{time.strftime('%Y%m%d-%H%M%S')}")
    options = RunOptions(
        plan_file=args.plan, verify=args.verify, trajectory=args.trajectory, simulate=args.simulate,
        sim_mu=args.sim_mu, sim_cf_offset=None if args.sim_cf_offset is None else tuple(args.sim_cf_offset),
        start_error=None if args.sim_start_error is None else _radians(args.sim_start_error),
        bumps=tuple(_radians(b) for b in args.sim_bump or ()),
        pose_noise=None if args.sim_pose_noise is None else _radians(args.sim_pose_noise),
        closed_loop=args.closed_loop, observe=args.observe,
        mjcf=None if args.mjcf is None else Path(args.mjcf), reach=args.reach,
        part=args.part, out=out, export_scene=None if args.export_scene is None else Path(args.export_scene))
    try:
        return Inputs(scene, options.checked(scene), planner_options)
    except SceneError as err:  # the library names its options' fields: the command, their flags
        raise SceneError(flag_of(err.field), err.problem) from None


def _radians(values: Sequence[float]) -> tuple[float, ...]:
    """The flag's values with the last, in degrees, in radians.

    >>> _radians([0.02, 0.0, 90.0])
    (0.02, 0.0, 1.5707963267948966)
    """
    return (*map(float, values[:-1]), math.radians(values[-1]))


def main(argv: list[str] | None = None) -> int:
    # One BLAS thread, set before numpy is first loaded: the command forks its recorder and region
    # workers, which is safe only in a process with one thread (planner.model.processes), and its
    # matrices are far too small for BLAS threads to pay.
    os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")
    # Only where the signals are Python's defaults: a process started with Ctrl-C ignored must go on ignoring it.
    loading = ({s: signal.signal(s, _stop_while_loading) for s in (signal.SIGINT, signal.SIGTERM)
                if signal.getsignal(s) in (signal.default_int_handler, signal.SIG_DFL)}
               if threading.current_thread() is threading.main_thread() else {})
    from .model.fields import FileFieldError, SceneError
    from .model.stop import Terminated, raise_on_sigterm
    from .pipeline import OutputError

    for signum, handler in loading.items():  # loaded: handled below from here on
        signal.signal(signum, handler)
    atexit.register(_silence_nanobind_leak_report)
    try:
        with raise_on_sigterm():
            if _is_batch(args := parser().parse_args(argv)):
                from .batch.command import run_command

                if args.export_scene is not None:
                    raise SceneError("--export-scene", "is for one plan, not a batch (several scenes or --seeds)")
                return run_command(args)
            return _run(args, read_inputs(argv))
    except SceneError as err:
        print(f"plan: error: {err if isinstance(err, FileFieldError) else SceneError(flag_of(err.field), err.problem)}",
              file=sys.stderr)
        return 1
    except OutputError as err:
        print(f"plan: error: {err}", file=sys.stderr)
        return 4
    except KeyboardInterrupt:
        print("plan: interrupted", file=sys.stderr)
        return 130
    except Terminated:
        print("plan: terminated", file=sys.stderr)
        return 143


def _is_batch(args: argparse.Namespace) -> bool:
    """Several scenes, or a seed range, make a batch (planner.batch.command)."""
    return len(args.scene) > 1 or args.seeds is not None


def _run(args: argparse.Namespace, inputs: Inputs) -> int:
    """Run ``inputs`` (:func:`planner.pipeline.run`), saying what is going on where a person
    watches, and print the outcome: its lines, or why there is no plan; the exit code."""
    from .pipeline import run

    scene, options, planner_options = inputs
    for note in scene.notes:
        print(f"plan: note: {note}", file=sys.stderr)
    tty = sys.stderr.isatty() and options.plan_file is None  # scripts get just the one line of outcome
    if tty:
        print(f"planning {scene.name} with {planner_options.name} (seed {planner_options.seed}, limit "
              f"{planner_options.time_limit:g} s) ...", file=sys.stderr, flush=True)
    reach_map = None
    if args.engine is not None or args.jobs is not None:  # the map's headings on the batch executors
        import functools

        from .batch.reach import reachable_set_on

        reach_map = functools.partial(_mapped_on, reachable_set_on, (args.engine or "local", args.jobs, args.address))
    outcome = run(scene, options, planner_options, progress=_progress if tty else None, reach_map=reach_map)
    if tty:
        print("\r\033[K", end="", file=sys.stderr, flush=True)  # clear the progress line
    if outcome.plan.note and outcome.plan.solved:
        print(f"plan: note: {outcome.plan.note}", file=sys.stderr)
    if (problem := outcome.problem()) is not None:
        print(f"plan: {problem} (outputs in {outcome.out})", file=sys.stderr)
    else:
        print("\n".join(outcome.lines()))
    return outcome.code


def _mapped_on(reachable_set_on, engine: tuple, scene: Scene, pushes: int, *, regions: str, margin: Margin):
    return reachable_set_on(scene, pushes, *engine, regions=regions, margin=margin)


def _progress(k: int, n: int) -> None:
    """One line on the terminal, rewritten for each stable region computed."""
    print(f"\rcomputing stable regions: edge {k} of {n}", end="", file=sys.stderr, flush=True)


def _fresh_folder(base: Path) -> Path:
    """``base``, or ``base-2``, ``base-3``... if runs started in the same second took it."""
    out, k = base, 1
    while out.exists():
        k += 1
        out = base.with_name(f"{base.name}-{k}")
    return out


if __name__ == "__main__":
    sys.exit(main())
