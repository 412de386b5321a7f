"""The ``plan`` command: plan a scene, print a summary, write the plan JSON and a rerun recording.

``--verify N`` then re-simulates the plan under N support distributions (:func:`planner.verify`)
and prints a line per push and an overall line with the worst deviation; ``--verify N --plan
FILE`` verifies a plan file instead of planning, once it is found to be a plan for the scene
(:func:`planner.execution.fit.fit_plan`), and writes the same outputs (the plan as run from the
scene's start, and a recording with the simulated ghost). ``--plan`` without ``--verify`` is bad input.
``--trajectory`` also writes the pusher's time-parameterised trajectory of a solved (or loaded)
plan, ``<name>.trajectory.csv`` (:func:`planner.execution.trajectory.trajectory`, default limits).
``--simulate N`` runs the whole plan (solved or loaded) open-loop in MuJoCo once per support
distribution (:func:`planner.execution.mujoco_sim.simulate`; ``--sim-mu``, ``--sim-cf-offset``
change the simulated friction and centre of pressure, ``--mjcf FILE`` writes the first run's model)
and prints a line per run and a summary line; MuJoCo is imported only then.
``--reach N`` (1 or 2) then maps the goal positions reachable from the start in at most N stable
pushes (:func:`planner.queries.reachable_set.reachable_set`, any heading): ``<name>-reach.png`` in the
output folder and ``/world/reach`` in the recording; with ``--engine`` (and ``--jobs``) its headings
are computed on the batch executors (:func:`planner.batch.reach.reachable_set_on`). Several scenes,
or ``--seeds``, make a batch instead (:mod:`planner.batch.command`). ``--export-scene FILE`` also
writes the scene as planned in the plain schema (:func:`planner.model.scene_file.write_scene`: CAD
files and boxes resolved to vertices, the CF written out).

Exit codes: 0 solved (and verified, if asked), 1 bad input (one line naming the field), 2 not
solved or certified unreachable (:func:`planner.certify_unreachable`, checked before planning; one
line saying why; nothing is verified), 3 verified and some push slipped beyond the
tolerance, or a simulated run missed the goal, slipped or collided, 4 an output could not be written (one line naming the file), 130 Ctrl-C and 143
SIGTERM (:mod:`planner.model.stop`). Output files are written atomically and checked
(:mod:`planner.model.files`), so an interrupted or failed run leaves no half-written file.
:func:`read_inputs` checks everything a run reads before anything is computed or written.
"""

from __future__ import annotations

import argparse
import atexit
import math
import os
import signal
import sys
import tempfile
import threading
import time
from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

# One BLAS thread, set before numpy is first loaded (planner's own import loads nothing): the
# command forks its recorder and region workers, which is safe only in a process with one thread
# (planner.model.processes), and its matrices are far too small for BLAS threads to pay.
os.environ.setdefault("OPENBLAS_NUM_THREADS", "1")


def _stop_while_loading(signum: int, frame) -> None:
    # Ctrl-C or SIGTERM while the modules below load: nothing runs or is written yet, so the
    # command ends at once with the one line main() would print, not an import's traceback.
    os.write(2, b"plan: interrupted\n" if signum == signal.SIGINT else b"plan: terminated\n")
    os._exit(128 + signum)


# Only where the signals are Python's defaults: a process started with Ctrl-C ignored (a child
# that imports the command's module) must go on ignoring it.
_LOADING = ({s: signal.signal(s, _stop_while_loading) for s in (signal.SIGINT, signal.SIGTERM)
             if signal.getsignal(s) in (signal.default_int_handler, signal.SIG_DFL)}
            if threading.current_thread() is threading.main_thread() else {})

from .model.fields import SceneError, shown  # noqa: E402 (after the environment is set)
from .model.extras import have, needs
from .model.files import atomic_path, staged_folder, write_atomic
from .model.plan import Plan
from .model.plan_file import load_plan
from .model.stop import Terminated, raise_on_sigterm
from .queries.reachability import certify_unreachable
from .outputs.recorder import RecordingFailed, recorder
from .actions.region_cache import cache_folder
from .model.options import (DEFAULT_PLANNER, DEFAULT_REGIONS, DEFAULT_SWITCH_COST, DEFAULT_TRANSIT, MAX_OPTIMIZE,
                            MAX_SEED, MAX_TIME_LIMIT, PLANNERS, REGIONS, TRANSITS, PlannerOptions)
from .model.scene import Scene
from .model.scene_file import placement_fault, write_scene
from .model.scene_file import load_scene
from .queries.session import plan

for _signal, _handler in _LOADING.items():  # loaded: main() handles them from here on
    signal.signal(_signal, _handler)

if TYPE_CHECKING:
    from .execution.trajectory import Trajectory
    from .execution.closed_loop import ClosedLoop
    from .execution.mujoco_sim import Simulation
    from .execution.verify import Verification

__all__ = ["Inputs", "main", "read_inputs"]

_EPILOG = f"""\
exit codes:
  0    solved (and verified, with --verify)
  1    bad input, in the scene (a goal in an obstacle, say), in an option's value (--reach 3),
       an extra that an option needs and is not installed (--reach without matplotlib) or
       a --plan file that is not a plan for the scene (another start, goal, part, or through a
       wall): one line "plan: error: <field>: <problem>", nothing written
  2    not solved within the time limit, or the goal is certified unreachable (one line
       "plan: unreachable: <reason> (outputs in <dir>)", at once); the files are still written,
       "solved": false with the reason; or a usage error (an unknown option, a missing value)
  3    --verify: a push slips in the simulator; --simulate: a run in MuJoCo misses the goal,
       slips or collides
  4    an output could not be written: one line "plan: error: cannot write <file>: <OS error>";
       no file is left in its place (a file already there is kept as it was); the output
       folder and --mjcf's are tried before planning
  130  interrupted (Ctrl-C), 143 terminated (SIGTERM): nothing is written, no process is left

Defaults: a scene's planner: mapping (and pusher.transit) sets its own, which these options
override; without them --planner {DEFAULT_PLANNER}, --time-limit {PlannerOptions.time_limit:g}, \
--seed {PlannerOptions.seed}, --regions {DEFAULT_REGIONS}, --transit {DEFAULT_TRANSIT}.
Exact regions are computed once per part (about 0.1-0.25 s an edge, one per core at a time;
the time limit bounds them and the search together, and they may take half of it) and cached in
$STABLEPUSH_CACHE, else $XDG_CACHE_HOME/stablepush or ~/.cache/stablepush (here: {{cache}})."""


def _silence_nanobind_leak_report() -> None:
    # nanobind reports OMPL objects still alive at interpreter exit on stderr; harmless noise
    # (docs/stack.md, "Leak report at exit"). Runs before finalisation, after everything of ours is flushed.
    sys.stdout.flush()
    sys.stderr.flush()
    os.dup2(os.open(os.devnull, os.O_WRONLY), 2)


def _parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="plan", description="Plan guaranteed-stable pushes for a YAML scene.",
                                epilog=_EPILOG.format(cache=cache_folder()),
                                formatter_class=argparse.RawDescriptionHelpFormatter)
    p.add_argument("scene", nargs="+", help="scene file (YAML; its format is in the README); several make a batch")
    p.add_argument("--planner", choices=PLANNERS, help=f"OMPL control planner (default: the scene's, else {DEFAULT_PLANNER})")
    p.add_argument("--time-limit", type=float, metavar="S",
                   help=f"planning time limit in seconds, at most {MAX_TIME_LIMIT:g} (default: the scene's, "
                        f"else {PlannerOptions.time_limit:g})")
    p.add_argument("--seed", type=int, metavar="N",
                   help=f"random seed, 1..{MAX_SEED}; the same seed gives the same plan (default: the scene's, "
                        f"else {PlannerOptions.seed})")
    p.add_argument("--regions", choices=REGIONS,
                   help=f"stable pushes: procedure STABLE or the exact region (default: the scene's, else {DEFAULT_REGIONS})")
    p.add_argument("--transit", choices=TRANSITS,
                   help=f"how the pusher may change edges: walk round the part, be lifted, or never "
                        f"(default: the scene's pusher.transit, else {DEFAULT_TRANSIT})")
    p.add_argument("--switch-cost", type=float, metavar="M",
                   help=f"what a switch of edge costs, in metres of the part's path, >= 0 (default: the scene's "
                        f"planner.switch_cost, else {DEFAULT_SWITCH_COST:g})")
    p.add_argument("--optimize", type=int, metavar="N",
                   help=f"after the first plan, N improvement rounds (0..{MAX_OPTIMIZE}) within --time-limit: odd "
                        "rounds search again, each with its own seed drawn from --seed; even rounds move the plan's "
                        "switch poses (or a via pose) on ever finer grids; the cheapest plan is kept (default: the "
                        "scene's planner.optimize, else 0)")
    p.add_argument("--out", metavar="DIR", help="output folder (default: logs/<name>-<timestamp>/)")
    p.add_argument("--verify", type=int, metavar="N",
                   help="re-simulate the plan under N support distributions; exit 3 if a push slips")
    p.add_argument("--plan", metavar="FILE",
                   help="with --verify or --simulate: check this plan file instead of planning")
    p.add_argument("--reach", type=int, metavar="N",
                   help="after planning, map the goal positions reachable from the start in at most N (1 or 2) "
                        "stable pushes, at any heading: <name>-reach.png in the output folder and /world/reach "
                        "in the recording (planner.queries.reachable_set; seconds per map)")
    p.add_argument("--trajectory", action="store_true",
                   help="for a solved (or loaded) plan, also write <name>.trajectory.csv: the pusher's pose and "
                        "velocity sampled at 100 Hz, jerk-limited, at rest wherever the push or edge changes, no "
                        "point of it faster than 0.05 m/s or accelerating more than 0.5 m/s^2 "
                        "(planner.execution.trajectory)")
    p.add_argument("--simulate", type=int, metavar="N",
                   help="run the whole plan open-loop in MuJoCo on N support distributions (a grid, extreme and "
                        "random foot triangles round the CF); exit 3 if a run misses the goal tolerance, slips or "
                        "collides (needs the mujoco extra: pip install 'stablepush[mujoco]')")
    p.add_argument("--sim-mu", type=float, metavar="MU",
                   help="with --simulate: pusher-part friction of the simulation (default: the planned pusher.mu)")
    p.add_argument("--sim-cf-offset", type=float, nargs=2, metavar=("DX", "DY"),
                   help="with --simulate: move the supports' centre of pressure by this offset from the CF "
                        "(slider frame, m)")
    p.add_argument("--sim-start-error", type=float, nargs=3, metavar=("DX", "DY", "DTHETA"),
                   help="with --simulate: the part starts this far from the plan's start (world frame; m, m, "
                        "degrees); every run begins with the pusher behind the first contact, moving in")
    p.add_argument("--sim-bump", type=float, nargs=4, action="append", metavar=("T", "DX", "DY", "DTHETA"),
                   help="with --simulate: T seconds after the pusher starts moving, the part is knocked this far "
                        "(world frame; m, m, degrees); may be given several times")
    p.add_argument("--sim-pose-noise", type=float, nargs=2, metavar=("SIGMA_M", "SIGMA_DEG"),
                   help="with --simulate: Gaussian noise on the part pose the closed loop observes (m per axis, degrees; "
                        "an open loop observes nothing)")
    p.add_argument("--closed-loop", action="store_true",
                   help="with --simulate: observe the part at 20 Hz and re-plan from where it is when it strays from "
                        "the plan (planner.execution.tracker); the summary counts the re-plans; with --trajectory "
                        "each run's executed pusher path is written as <name>.executed.csv (the first run), "
                        "<name>.executed-<k>.csv (run k)")
    p.add_argument("--mjcf", metavar="FILE", help="with --simulate: write the first run's MuJoCo model (MJCF XML)")
    p.add_argument("--export-scene", metavar="FILE",
                   help="also write the scene as planned to FILE (YAML, the plain schema: CAD files and boxes "
                        "resolved to vertices in metres, the CF and the pushed edges written out)")
    batch = p.add_argument_group("batch runs (several scenes, or --seeds; planner.batch)")
    batch.add_argument("--seeds", metavar="A:B", help="plan each scene for seeds A to B (or N, or A,B,C)")
    batch.add_argument("--jobs", type=int, metavar="N", help="tasks at once (default: the cores, or the Ray cluster's CPUs)")
    batch.add_argument("--engine", choices=("local", "ray"),
                       help="where tasks (and --reach's map) run: processes of this machine (default) or Ray")
    batch.add_argument("--address", metavar="ADDR", help="with --engine ray: an existing cluster's (default: start one)")
    batch.add_argument("--resume", action="store_true", help="run only the tasks of --out DIR without a result")
    return p


@dataclass(frozen=True)
class Inputs:
    """A command line, checked: the scene with the flags applied, and what to do with it."""

    scene: Scene  # with --regions and --transit applied
    planner: str
    time_limit: float
    seed: int
    out: Path  # the output folder (not created yet)
    verify: int | None  # --verify N
    plan_path: str | None  # --plan FILE
    given: Plan | None  # that file's plan, checked against the scene and run from its start, instead of planning
    reach: int | None = None  # --reach N: pushes of the reachable-set map
    engine: tuple[str, int | None, str | None] | None = None  # --engine, --jobs, --address: where the map runs
    trajectory: bool = False  # --trajectory: write the pusher's trajectory
    simulate: int | None = None  # --simulate N: runs in MuJoCo
    sim_mu: float | None = None  # --sim-mu
    sim_cf_offset: tuple[float, float] = (0.0, 0.0)  # --sim-cf-offset
    mjcf: Path | None = None  # --mjcf FILE
    export_scene: Path | None = None  # --export-scene FILE
    start_error: tuple[float, float, float] = (0.0, 0.0, 0.0)  # --sim-start-error, theta in radians
    bumps: tuple[tuple[float, float, float, float], ...] = ()  # --sim-bump, theta in radians
    pose_noise: tuple[float, float] = (0.0, 0.0)  # --sim-pose-noise, theta in radians
    closed_loop: bool = False  # --closed-loop


def read_inputs(argv: Sequence[str] | None = None) -> Inputs:
    """Parse and check the command line ``argv`` and read the files it names, computing and
    writing nothing: every bad input is found here, before any planning.

    Raises
    ------
    SceneError
        Naming the flag or field at fault.
    SystemExit
        On argparse's usage errors (code 2) and ``--help`` (code 0).
    """
    args = _parser().parse_args(argv)
    if args.verify is not None and args.verify < 1:
        raise SceneError("--verify", f"must be at least 1 distribution, got {args.verify}")
    if args.plan is not None and args.verify is None and args.simulate is None:
        raise SceneError("--plan", "needs --verify N or --simulate N: a plan file is only read to be checked")
    _check_simulation(args)
    if args.reach is not None and args.reach not in (1, 2):
        raise SceneError("--reach", f"must be 1 or 2 pushes, got {args.reach}")
    if args.reach is not None and not have("matplotlib"):  # found before the work, not after it
        raise SceneError("--reach", f"the map's PNG {needs('matplotlib')}")
    for flag, value in (("--engine", args.engine), ("--jobs", args.jobs), ("--address", args.address)):
        if value is not None and args.reach is None:
            raise SceneError(flag, "is for a batch (several scenes or --seeds) or a --reach map")
    if _is_batch(args) or args.resume:
        raise SceneError("--resume" if args.resume else "scene", "several scenes, --seeds or --resume make a batch, "
                                                               "which the plan command runs itself (planner.batch)")
    scene = load_scene(args.scene[0])
    if len(scene.parts) > 1:
        _check_parts(args)
    if args.sim_cf_offset is not None:
        from .execution.mujoco_sim import support_centre

        for name in scene.names:
            support_centre(scene.move_scene(name, scene.starts), args.sim_cf_offset)
    if args.sim_start_error is not None:  # found now; the rest (the pusher's lead-in, the bumps) once planned
        moved = scene.start + _radians(args.sim_start_error)
        if (fault := placement_fault(scene.slider, scene.obstacles, scene.workspace, moved)) is not None:
            raise SceneError("--sim-start-error", f"puts the part where it cannot be: {fault}")
    # The search, the one-step check, the recording and verify's check of lifts all read the
    # options from the scene as planned.
    scene = scene.with_options(options_of(args, scene.planner))
    out = Path(args.out) if args.out else _fresh_folder(Path("logs") / f"{scene.name}-{time.strftime('%Y%m%d-%H%M%S')}")
    try:
        taken = out.exists() and not out.is_dir()
    except (OSError, ValueError) as err:  # a name too long, or with a NUL
        raise SceneError("--out", f"cannot use {shown(str(out))}: {getattr(err, 'strerror', None) or err}") from None
    if taken:  # found now, not after the search
        raise SceneError("--out", f"{shown(str(out))} exists and is not a folder")
    # Where the outputs go is tried now, before the work whose results would have nowhere to go.
    _check_writable(out, out)
    if args.mjcf is not None and _within(Path(args.mjcf), out, out) == Path(args.mjcf):
        _check_writable(Path(args.mjcf).parent, Path(args.mjcf))
    if args.export_scene is not None and os.path.isdir(args.export_scene):
        raise SceneError("--export-scene", f"{shown(args.export_scene)} is a folder")
    given = None
    if args.plan is not None and len(scene.parts) > 1:
        from .execution.fit import fit_parts_plan  # with the re-simulator: only for a plan file
        given = fit_parts_plan(scene, load_plan(args.plan))
    elif args.plan is not None:
        from .execution.fit import fit_plan  # with the re-simulator: only for a plan file

        given = fit_plan(scene, load_plan(args.plan))
    return Inputs(scene, scene.planner.name, scene.planner.time_limit, scene.planner.seed, out, args.verify, args.plan,
                  given, args.reach,
                  None if args.engine is None and args.jobs is None else (args.engine or "local", args.jobs, args.address),
                  args.trajectory, args.simulate,
                  args.sim_mu, tuple(args.sim_cf_offset or (0.0, 0.0)), None if args.mjcf is None else Path(args.mjcf),
                  None if args.export_scene is None else Path(args.export_scene),
                  _radians(args.sim_start_error or (0.0, 0.0, 0.0)),
                  tuple(_radians(b) for b in args.sim_bump or ()), _radians(args.sim_pose_noise or (0.0, 0.0)),
                  args.closed_loop)


def _radians(values: Sequence[float]) -> tuple[float, ...]:
    """The flag's values with the last, in degrees, in radians.

    >>> _radians([0.02, 0.0, 90.0])
    (0.02, 0.0, 1.5707963267948966)
    """
    return (*map(float, values[:-1]), math.radians(values[-1]))


#: The flag of each planner option (:class:`~planner.model.options.PlannerOptions`' fields).
FLAGS = {"name": "--planner", "time_limit": "--time-limit", "seed": "--seed", "regions": "--regions",
         "switch_cost": "--switch-cost", "optimize": "--optimize", "transit": "--transit"}


#: The arguments the library names as fields (its errors never name a flag), with their flags
#: (the options' are :data:`FLAGS`, turned by :func:`options_of`: ``name`` is also a scene's field).
ARGUMENTS = {"seed": "--seed", "cf_offset": "--sim-cf-offset", "start_error": "--sim-start-error",
             "bump": "--sim-bump", "pose_noise": "--sim-pose-noise",
             **{name: f"--{name.replace('_', '-')}" for name in
                ("engine", "jobs", "address", "out", "seeds", "resume", "simulate", "verify", "reach",
                 "trajectory", "sim_mu", "sim_cf_offset", "mjcf", "closed_loop")}}


def flag_of(field: str) -> str:
    """The flag of an argument the library names ``field``; any other field as it is.

    >>> flag_of("jobs"), flag_of("cf_offset"), flag_of("slider.cf")
    ('--jobs', '--sim-cf-offset', 'slider.cf')
    """
    return ARGUMENTS.get(field, field)


def options_of(args: argparse.Namespace, options: PlannerOptions) -> PlannerOptions:
    """``options`` with the planner flags given applied; an error names the flag."""
    changes = {field: value for field, flag in FLAGS.items()
               if (value := getattr(args, flag[2:].replace("-", "_"), None)) is not None}
    try:
        return options.merged(changes)
    except SceneError as err:
        raise SceneError(FLAGS[err.field], err.problem) from None


def _check_simulation(args: argparse.Namespace) -> None:
    """Refuse the simulation flags without ``--simulate``, bad values, and ``--simulate`` without MuJoCo."""
    for flag, value in (("--sim-mu", args.sim_mu), ("--sim-cf-offset", args.sim_cf_offset), ("--mjcf", args.mjcf),
                        ("--sim-start-error", args.sim_start_error), ("--sim-bump", args.sim_bump),
                        ("--sim-pose-noise", args.sim_pose_noise), ("--closed-loop", args.closed_loop or None)):
        if value is not None and args.simulate is None:
            raise SceneError(flag, "needs --simulate N")
    if args.simulate is None:
        return
    for flag, values in (("--sim-start-error", args.sim_start_error), ("--sim-pose-noise", args.sim_pose_noise),
                         *(("--sim-bump", b) for b in args.sim_bump or ())):
        if values is not None and not all(abs(v) < float("inf") for v in values):
            raise SceneError(flag, f"must be finite, got {' '.join(map(str, values))}")
    if args.sim_pose_noise is not None and min(args.sim_pose_noise) < 0:
        raise SceneError("--sim-pose-noise", f"standard deviations must be >= 0, got {' '.join(map(str, args.sim_pose_noise))}")
    if any(b[0] < 0 for b in args.sim_bump or ()):
        raise SceneError("--sim-bump", "a bump's time must be >= 0")
    if args.simulate < 1:
        raise SceneError("--simulate", f"must be at least 1 distribution, got {args.simulate}")
    if args.sim_mu is not None and not 0 < args.sim_mu < float("inf"):
        raise SceneError("--sim-mu", f"must be a positive friction coefficient, got {args.sim_mu}")
    if args.sim_cf_offset is not None and not all(abs(v) < float("inf") for v in args.sim_cf_offset):
        raise SceneError("--sim-cf-offset", f"must be finite, got {args.sim_cf_offset}")
    from .execution.mujoco_sim import needs_mujoco

    needs_mujoco()


#: The flags a multi-part scene does not take yet: maps and the closed loop's perturbations.
_ONE_PART = ("--reach", "--sim-start-error", "--sim-bump", "--sim-pose-noise", "--closed-loop", "--engine", "--jobs",
             "--address")


def _check_parts(args: argparse.Namespace) -> None:
    """Refuse the flags a multi-part scene does not take."""
    for flag in _ONE_PART:
        if getattr(args, flag[2:].replace("-", "_")) not in (None, False):
            raise SceneError(flag, "is for one-part scenes (slider, start, goal), not a scene with parts")


def main(argv: list[str] | None = None) -> int:
    atexit.register(_silence_nanobind_leak_report)
    try:
        with raise_on_sigterm():
            if _is_batch(args := _parser().parse_args(argv)):
                from .batch.command import run_command

                if args.export_scene is not None:
                    raise SceneError("--export-scene", "is for one plan, not a batch (several scenes or --seeds)")

                return run_command(args)
            return _run(read_inputs(argv))
    except SceneError as err:
        print(f"plan: error: {SceneError(flag_of(err.field), err.problem)}", file=sys.stderr)
        return 1
    except _NotWritten as err:
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


class _NotWritten(Exception):
    """An output file could not be written (the message names it and says why)."""


def _run(inputs: Inputs) -> int:
    for note in inputs.scene.notes:
        print(f"plan: note: {note}", file=sys.stderr)
    if len(inputs.scene.parts) > 1:
        return _plan_parts(inputs)
    with recorder(inputs.scene) as write:  # rerun is imported beside the search, where it can be
        return _plan_and_write(inputs, write)


def _plan_and_write(inputs: Inputs, write_recording: Callable[..., None]) -> int:
    scene, out, name, seed, limit = inputs.scene, inputs.out, inputs.planner, inputs.seed, inputs.time_limit
    unreachable = None
    if inputs.given is not None:
        result = inputs.given
    else:
        tty = sys.stderr.isatty()  # a search can take seconds; scripts get just the one line of outcome
        if tty:
            print(f"planning {scene.name} with {name} (seed {seed}, limit {limit:g} s) ...", file=sys.stderr,
                  flush=True)
        clock = time.perf_counter()
        # The geometric certificates need no stable region: a sealed-off goal is answered at once.
        unreachable = certify_unreachable(scene, regions=False)
        result = (Plan.of_part(scene.part().name, scene.start, scene.goal, [], scene=scene.path, solved=False,
                               planner=name, seed=seed, planning_time_s=time.perf_counter() - clock,
                               reason=unreachable) if unreachable
                  else plan(scene, seed=seed, time_limit=limit, planner=name, progress=_progress if tty else None))
        if tty:
            print("\r\033[K", end="", file=sys.stderr, flush=True)  # clear the progress line
        if result.note and result.solved:
            print(f"plan: note: {result.note}", file=sys.stderr)
    # The planning seed also draws the random distributions, so a run is repeatable as a whole.
    check = None
    if inputs.verify and result.solved:
        from .execution.verify import verify  # the re-simulator, loaded only for --verify

        check = verify(scene, result, inputs.verify, seed)
    motion = None
    if inputs.trajectory and result.solved:
        from .execution.trajectory import trajectory  # loads ruckig, only for --trajectory

        motion = trajectory(scene, result)
    simulation = None
    if inputs.simulate and result.solved:
        from .execution.mujoco_sim import simulate  # MuJoCo is loaded only for --simulate

        if inputs.closed_loop:
            from .execution.closed_loop import closed_loop
            from .queries.session import Planner

            session = Planner(scene)
            session.plan(start=result.start, seed=seed)  # a plan for the goal that re-plans are joined to
            simulation = closed_loop(session, result, inputs.simulate, seed, inputs.sim_mu, inputs.sim_cf_offset,
                                     inputs.start_error, inputs.bumps, inputs.pose_noise)
        else:
            simulation = simulate(scene, result, inputs.simulate, seed, inputs.sim_mu, inputs.sim_cf_offset,
                                  inputs.start_error, inputs.bumps)
    reach = None
    if inputs.reach:  # after planning: the map is about the start, whatever the plan
        if inputs.engine is None:
            from .queries.reachable_set import reachable_set

            reach = reachable_set(scene, inputs.reach)
        else:
            from .batch.reach import reachable_set_on

            reach = reachable_set_on(scene, inputs.reach, *inputs.engine)
    if inputs.export_scene is not None:
        _export_scene(scene, inputs)
    _write_outputs(out, scene, result, check, reach, motion, write_recording, simulation, inputs.mjcf,
                   inputs.closed_loop)
    if unreachable:
        print(f"plan: unreachable: {unreachable} (outputs in {out})", file=sys.stderr)
        return 2
    if not result.solved:
        print(f"plan: not solved: {result.reason} (outputs in {out})", file=sys.stderr)
        return 2
    head = (f"loaded {inputs.plan_path}: {result.contents()}"
            if inputs.given is not None
            else f"solved: {result.headline()}, "
                 f"planning time {result.planning_time_s:.2f} s{_first_found(result)}")
    executed = simulation.executed_files(scene.name) if motion is not None and inputs.closed_loop and simulation is not None else []
    executed = executed[:1] + ([f"... {executed[-1]}"] if len(executed) > 1 else [])
    extra = f"{f', {scene.name}.trajectory.csv' if motion else ''}{''.join(f', {f}' for f in executed)}{f', {scene.name}-reach.png' if reach else ''}"
    return _report(f"{head} -> {out}/{scene.name}.json, {scene.name}.rrd{extra}", check, simulation, out)


def _report(head: str, check, simulation, out: Path) -> int:
    """Print ``head``, then ``check``'s (a verification's) and ``simulation``'s lines and
    summaries where given, the last line saying where the files are; the exit code: 3 if either
    failed, else 0."""
    lines = [head]
    if check is not None:
        lines += [*check.lines(), f"{check.summary()} in {check.seconds:.1f} s"]
    if simulation is not None:
        lines += [*simulation.lines(), simulation.summary()]
    if len(lines) > 1:  # the last line says where the files are, whatever came before it
        lines[-1] += f" (outputs in {out})"
    print("\n".join(lines))
    return 0 if (check is None or check.passed) and (simulation is None or simulation.passed) else 3


def _plan_parts(inputs: Inputs) -> int:
    """Plan (or load) a multi-part plan, verify or simulate it if asked, and write its plan
    (``stablepush.plan/2``), recording and trajectory."""
    scene, out, seed = inputs.scene, inputs.out, inputs.seed
    if inputs.given is not None:
        result = inputs.given
    else:
        from .queries.session import Planner

        tty = sys.stderr.isatty()
        if tty:
            print(f"planning {scene.name}: {len(scene.parts)} parts with {inputs.planner} (seed {seed}, limit "
                  f"{inputs.time_limit:g} s) ...", file=sys.stderr, flush=True)
        result = Planner(scene, progress=_progress if tty else None).plan()
        if tty:
            print("\r\033[K", end="", file=sys.stderr, flush=True)
    check = motion = simulation = None
    if inputs.verify and result.solved:
        from .execution.parts_verify import verify_parts

        check = verify_parts(scene, result, inputs.verify, seed)
    if inputs.trajectory and result.solved:
        from .execution.trajectory import trajectory  # loads ruckig, only for --trajectory

        motion = trajectory(scene, result)
    if inputs.simulate and result.solved:
        from .execution.parts_sim import simulate_parts  # MuJoCo is loaded only for --simulate

        simulation = simulate_parts(scene, result, inputs.simulate, seed, inputs.sim_mu, inputs.sim_cf_offset)
    if inputs.export_scene is not None:
        _export_scene(scene, inputs)
    with _writing(out, scene.name) as stage:
        from .outputs.recording import write_recording  # rerun: only now

        write_recording(stage / f"{scene.name}.rrd", scene, result)
        if motion is not None:
            motion.write_csv(stage / f"{scene.name}.trajectory.csv")
        if simulation is not None and inputs.mjcf is not None:
            simulation.write_mjcf(_within(inputs.mjcf, out, stage), scene)
        write_atomic(stage / f"{scene.name}.json", result.to_json())
    if not result.solved:
        print(f"plan: not solved: {result.reason} (outputs in {out})", file=sys.stderr)
        return 2
    head = (f"loaded {inputs.plan_path}: {result.contents()}" if inputs.given is not None
            else f"solved: {result.headline()}, planning time {result.planning_time_s:.2f} s")
    extra = f", {scene.name}.trajectory.csv" if motion is not None else ""
    return _report(f"{head} -> {out}/{scene.name}.json, {scene.name}.rrd{extra}", check, simulation, out)


def _export_scene(scene: Scene, inputs: Inputs) -> None:
    """Write ``scene`` as planned (the flags' options merged into it) to ``--export-scene``'s file."""
    try:
        write_scene(scene, inputs.export_scene)
    except OSError as err:
        raise _NotWritten(f"cannot write {shown(str(inputs.export_scene))}: {err.strerror or err}") from None


def _first_found(result: Plan) -> str:
    """What the first plan cost and when it was found, when improvement rounds found better ones
    (cost against time: the answer only got better), else nothing.

    >>> plan = Plan.of_part("part", [0, 0, 0], [0, 0, 0], [], scene=None, solved=True, planner="rrt", seed=1,
    ...                     planning_time_s=2.5, improvements=[(0.4, 1.2, 0.95), (1.1, 0.8, 0.55)])
    >>> _first_found(plan)
    ' (first plan: cost 1.200 m at 0.40 s; 1 better, the last at 1.10 s)'
    """
    if len(result.improvements) < 2:
        return ""
    (t, c, _), later = result.improvements[0], len(result.improvements) - 1
    return f" (first plan: cost {c:.3f} m at {t:.2f} s; {later} better, the last at {result.improvements[-1][0]:.2f} s)"


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


def _write_outputs(out: Path, scene: Scene, result: Plan, check: Verification | None, reach,
                   motion: Trajectory | None, write_recording: Callable[..., None],
                   simulation: Simulation | ClosedLoop | None = None, mjcf: Path | None = None,
                   closed: bool = False) -> None:
    """Write the recording (with ``check``'s ghost, ``reach``'s map and ``simulation``'s worst run,
    by ``write_recording``), ``reach``'s PNG and the trajectory ``motion``'s CSV if given, the MJCF
    of ``simulation``'s first run to ``mjcf`` if both are given, and the plan JSON into ``out``,
    creating it if need be. The plan file comes last: where it is, the run wrote everything. A new
    ``out`` appears with all of them at once (:func:`~planner.model.files.staged_folder`). A closed
    loop's runs (``closed``) are drawn in the recording on their own clocks, their re-plans with
    them; with ``motion``, each run's executed pusher path is written beside it,
    ``<name>.executed.csv`` (the first run) and ``<name>.executed-<k>.csv`` (run k >= 2)."""
    with _writing(out, scene.name) as stage:
        # An open-loop run is drawn against its plan; a closed loop's runs against their own clocks.
        write_recording(stage / f"{scene.name}.rrd", scene, result, check, reach, None if closed else simulation,
                        simulation if closed else None)
        if reach is not None:
            from .queries.reachable_set import write_png

            with atomic_path(stage / f"{scene.name}-reach.png") as tmp:
                write_png(reach, scene, str(tmp))
        if motion is not None:
            motion.write_csv(stage / f"{scene.name}.trajectory.csv")
            if closed and simulation is not None:
                simulation.write_executed(stage, scene.name)
        if simulation is not None and mjcf is not None:
            simulation.write_mjcf(_within(mjcf, out, stage), scene)
        write_atomic(stage / f"{scene.name}.json", result.to_json())


@contextmanager
def _writing(out: Path, name: str) -> Iterator[Path]:
    """The folder to write ``out``'s files in (:func:`~planner.model.files.staged_folder`: a new
    ``out`` appears whole); a file that cannot be written, or a failed recording ``<name>.rrd``,
    is :class:`_NotWritten` naming the file as the user named it."""
    stage = out
    try:
        with staged_folder(out) as stage:
            yield stage
    except OSError as err:
        named = str(err.filename or out)
        if Path(named).parent == out.parent and Path(named).name.startswith(f".{out.name}."):
            named = str(out)  # the staged folder itself could not be made: the user named its target
        named = named.replace(str(stage), str(out), 1)  # a file as the user named it
        raise _NotWritten(f"cannot write {shown(named)}: {err.strerror or err}") from None
    except RecordingFailed as err:
        raise _NotWritten(f"cannot write {shown(str(out / f'{name}.rrd'))}: the recording failed: {err}") from None


def _check_writable(folder: Path, named: Path) -> None:
    """Raise :class:`_NotWritten` naming ``named`` unless a file can be made in ``folder`` or, if
    that does not exist yet, in the nearest folder above it that does (where it would be made).
    The test file is anonymous (``O_TMPFILE`` where there is one) and gone at once."""
    place = folder
    try:
        while not place.exists() and place != place.parent:
            place = place.parent
        with tempfile.TemporaryFile(dir=place):
            pass
    except (OSError, ValueError) as err:  # ValueError: a NUL in the name
        raise _NotWritten(f"cannot write {shown(str(named))}: {getattr(err, 'strerror', None) or err}") from None


def _within(path: Path, out: Path, stage: Path) -> Path:
    """``path``, or where it is written while ``out`` is staged if it lies in ``out``."""
    try:
        return stage / Path(path).resolve().relative_to(out.resolve())
    except ValueError:
        return Path(path)

if __name__ == "__main__":
    sys.exit(main())
