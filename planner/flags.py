"""The ``plan`` command's flags: the parser, with each flag's help and the exit codes, and how the
flags map to the library's names (:data:`FLAGS` for the planner's options, :data:`ARGUMENTS` for
the pipeline's, :func:`flag_of`), so that an error the library names by a field is printed with
the flag the user typed. Nothing here loads the planner until a parser is made.
"""

from __future__ import annotations

import argparse
import re
from typing import TYPE_CHECKING

if TYPE_CHECKING:
    from .model.options import PlannerOptions

__all__ = ["ARGUMENTS", "FLAGS", "flag_of", "options_of", "parser"]

#: The flag of each planner option (:class:`~planner.model.options.PlannerOptions`' fields).
FLAGS = {"name": "--planner", "time_limit": "--time-limit", "seed": "--seed", "regions": "--regions",
         "switch_cost": "--switch-cost", "optimize": "--optimize", "transit": "--transit", "margin": "--margin"}
#: The arguments the library names as fields (its errors never name a flag), with their flags
#: (the options' are :data:`FLAGS`, turned by :func:`options_of`: ``name`` is also a scene's field).
ARGUMENTS = {"seed": "--seed", "cf_offset": "--sim-cf-offset", "sim_cf_offset": "--sim-cf-offset",
             "start_error": "--sim-start-error", "bump": "--sim-bump", "bumps": "--sim-bump",
             "pose_noise": "--sim-pose-noise", "plan_file": "--plan",
             **{name: f"--{name.replace('_', '-')}" for name in
                ("engine", "jobs", "address", "out", "seeds", "resume", "simulate", "verify", "reach", "part",
                 "trajectory", "sim_mu", "mjcf", "closed_loop", "observe", "export_scene")}}


#: A negative number as float() reads it: -1, -.5, -1e-3, -2.5E+4, -inf, -nan.
_NEGATIVE = re.compile(r"^-(\d+\.?\d*|\.\d+)([eE][-+]?\d+)?$|^-(inf|infinity|nan)$", re.IGNORECASE)


def parser() -> argparse.ArgumentParser:
    from .actions.region_cache import cache_folder
    from .model.options import (DEFAULT_PLANNER, DEFAULT_REGIONS, DEFAULT_SWITCH_COST, DEFAULT_TRANSIT,
                                MAX_OPTIMIZE, MAX_SEED, MAX_TIME_LIMIT, PLANNERS, REGIONS, TRANSITS, PlannerOptions)

    epilog = f"""\
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
  130  interrupted (Ctrl-C), 143 terminated (SIGTERM): nothing is written (unless the signal
       came after the plan file, the last output, was in place), no process is left

Defaults: a scene's planner: mapping (and pusher.transit) sets its own, which these options
override; without them --planner {DEFAULT_PLANNER}, --time-limit {PlannerOptions.time_limit:g}, \
--seed {PlannerOptions.seed}, --regions {DEFAULT_REGIONS}, --transit {DEFAULT_TRANSIT}.
Exact regions are computed once per part (about 0.1-0.25 s an edge, one per core at a time;
the time limit bounds them and the search together, and they may take half of it) and cached in
$STABLEPUSH_CACHE, else $XDG_CACHE_HOME/stablepush or ~/.cache/stablepush (here: {cache_folder()})."""
    p = argparse.ArgumentParser(prog="plan", description="Plan guaranteed-stable pushes for a YAML scene.",
                                epilog=epilog, formatter_class=argparse.RawDescriptionHelpFormatter)
    # argparse takes "-1e-3" or "-inf" for an option (it knows negatives only as -1 and -.5), so
    # "--sim-start-error -1e-3 0 0" was "expected 3 arguments". No flag of ours looks like a number,
    # so every number in float's notation is a value; the checks then refuse what is not finite.
    p._negative_number_matcher = _NEGATIVE
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
    p.add_argument("--margin", type=float, nargs="+", metavar="F",
                   help="the stability margin every push keeps: MU CF, each a fraction in [0, 1): the pushes hold for "
                        "a pusher friction MU lower than the scene's and a CF anywhere within CF times the part's "
                        "radius (at least 1 mm) of the scene's; 0 plans at the regions' exact limit (default: the "
                        f"scene's planner.margin, else {PlannerOptions.margin.mu:g} {PlannerOptions.margin.cf:g})")
    p.add_argument("--out", metavar="DIR", help="output folder (default: logs/<name>-<timestamp>/)")
    p.add_argument("--verify", type=int, metavar="N",
                   help="re-simulate the plan under N support distributions; exit 3 if a push slips")
    p.add_argument("--plan", metavar="FILE",
                   help="with --verify or --simulate: check this plan file instead of planning")
    p.add_argument("--part", metavar="NAME", help="with --reach on a scene of several parts: the part to map, the "
                                                  "others obstacles where they stand")
    p.add_argument("--reach", type=int, metavar="N",
                   help="after planning, map the goal positions reachable from the start in at most N (1 or 2) "
                        "stable pushes, at any heading: <name>-reach.png in the output folder and /world/reach "
                        "in the recording (planner.queries.reachable_set; seconds per map)")
    p.add_argument("--trajectory", action="store_true",
                   help="for a solved (or loaded) plan, also write <name>.trajectory.csv: the pusher's pose and "
                        "velocity sampled at 100 Hz, jerk-limited, at rest wherever the push or edge changes, no "
                        "point of it faster than 0.05 m/s or accelerating more than 0.5 m/s^2 "
                        "(planner.execution.trajectory); with a robot: block, also <name>.joints.csv, the arm's "
                        "joints along it, and exit 3 if the arm cannot follow it (planner.arm, docs/arm.md)")
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
                        "the plan (planner.execution.tracker; a tray's parts each, its moves left re-planned as each "
                        "move ends); the summary counts the re-plans; with --trajectory "
                        "each run's executed pusher path is written as <name>.executed.csv (the first run), "
                        "<name>.executed-<k>.csv (run k)")
    p.add_argument("--observe", choices=("truth", "camera"),
                   help="with --closed-loop: what the loop sees the parts with: truth, MuJoCo's poses with "
                        "--sim-pose-noise (the default), or camera, the scene's depth camera (its camera: block, or "
                        "the default camera of the workspace) and the pose estimator (planner.perception); each "
                        "run's line then gives the estimates' errors against MuJoCo's poses and the time lost")
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


def flag_of(field: str) -> str:
    """The flag of an argument the library names ``field``; any other field as it is.

    >>> flag_of("jobs"), flag_of("cf_offset"), flag_of("slider.cf")
    ('--jobs', '--sim-cf-offset', 'slider.cf')

    A batch's tasks name what the flags change of each scene ``overrides.<option>``:

    >>> flag_of("overrides.margin"), flag_of("overrides.planner")
    ('--margin', '--planner')
    """
    if field.startswith("overrides."):
        key = field.removeprefix("overrides.")
        return FLAGS.get("name" if key == "planner" else key, field)
    return ARGUMENTS.get(field, field)


def options_of(args: argparse.Namespace, options: PlannerOptions) -> PlannerOptions:
    """``options`` with the planner flags given applied; an error names the flag."""
    from .model.fields import SceneError

    changes = {field: value for field, flag in FLAGS.items()
               if (value := getattr(args, flag[2:].replace("-", "_"), None)) is not None}
    try:
        return options.merged(changes)
    except SceneError as err:
        raise SceneError(FLAGS[err.field], err.problem) from None
