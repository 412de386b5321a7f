"""One run of the pipeline: certify or plan, check, simulate, map and write (:func:`run`).

Output files are written atomically and checked (:mod:`planner.model.files`), in a folder staged
beside the one asked for where that is new (:func:`~planner.model.files.staged_folder`), so that
an interrupted or failed run leaves no half-written file; the plan file comes last. Where they go
is tried before any work whose results would have nowhere to go.
"""

from __future__ import annotations

import tempfile
from collections.abc import Callable, Iterator
from collections.abc import Mapping
from contextlib import contextmanager, nullcontext
from dataclasses import replace
from pathlib import Path
from typing import Any

from ..actions.margins import with_margins
from ..model.fields import SceneError, shown
from ..model.files import atomic_path, staged_folder, write_atomic
from ..model.options import PlannerOptions
from ..model.plan import Plan
from ..model.plan_file import load_plan
from ..model.scene import Scene
from ..outputs.recorder import RecordingFailed, recorder
from ..queries.reachability import certify_unreachable
from ..queries.session import Planner, session_options
from .options import RunOptions
from .outcome import Outcome, OutputError

__all__ = ["check_outputs", "run"]

#: A function mapping a one-part scene's reachable set in at most N pushes with the stable pushes of
#: a ``regions`` option (``reach_map(scene, n, regions=regions)``).
ReachMap = Callable[..., object]


def run(scene: Scene, options: RunOptions = RunOptions(),
        planner_options: PlannerOptions | Mapping[str, Any] | None = None, *,
        progress: Callable[[int, int], None] | None = None, reach_map: ReachMap | None = None) -> Outcome:
    """Run ``scene`` as ``options`` ask (module docstring of :mod:`planner.pipeline`): the plan
    read from ``options.plan_file`` and fitted to the scene, or else the goal's certificate of
    unreachability (one part: the geometry's, at once) or a plan of a :class:`Planner` session
    (``progress(k, n)`` before each region it computes); then the checks, the simulation (closed
    loop on the same session), the map (by ``reach_map``, default: this process) and the outputs
    in ``options.out``.

    ``planner_options`` are the planner's, resolved once as a session resolves them
    (:func:`~planner.queries.session.session_options`: a
    :class:`~planner.model.options.PlannerOptions`, or a mapping of changes to the scene's own;
    default: the scene's own) and used by every step: the session plans with them, the plan file
    and the checks allow the transits their ``transit`` allows, the map uses their ``regions``,
    and ``export_scene`` writes them. Their seed plans and draws every random distribution, so a
    run is repeatable as a whole.

    Raises
    ------
    SceneError
        For options that do not fit the scene, or a plan file that is not a plan for it.
    OutputError
        If an output cannot be written (the message names the file).
    """
    options = options.checked(scene)
    planner_options = session_options(scene, planner_options)
    if options.out is not None:
        check_outputs(options)
    loaded = None if options.plan_file is None else _fitted(scene, options.plan_file, planner_options.transit)
    # The recording's process is forked before the search, while this one runs one thread.
    with recorder(scene) if options.out is not None else nullcontext() as write_recording:
        session, unreachable = None, None
        if loaded is not None:
            result = loaded
        else:
            # The geometric certificates need no stable region: a sealed-off goal is answered at once.
            unreachable = certify_unreachable(scene, regions=False) if len(scene.parts) == 1 else None
            if unreachable:
                result = Plan.of_part(scene.part().name, scene.start, scene.goal, [], scene=scene.path, solved=False,
                                      planner=planner_options.name, seed=planner_options.seed,
                                      planning_time_s=0.0, reason=unreachable, margin=planner_options.margin)
            else:
                session = Planner(scene, planner_options, progress=progress)
                result = session.plan(since=session.clock)  # the time limit bounds the regions too
        outcome = _checked(scene, options, planner_options, with_margins(scene, result), session, reach_map)
        outcome = replace(outcome, loaded=None if loaded is None else str(options.plan_file), unreachable=unreachable)
        if options.out is not None:
            outcome = replace(outcome, out=options.out,
                              files=_write(outcome, options, planner_options, write_recording))
    return outcome


def _fitted(scene: Scene, path: str | Path, transit: str) -> Plan:
    from ..execution.fit import fit_plan  # with the re-simulator: only for a plan file

    return fit_plan(scene, load_plan(path), transit=transit)


def _checked(scene: Scene, options: RunOptions, planner_options: PlannerOptions, result: Plan,
             session: Planner | None, reach_map: ReachMap | None) -> Outcome:
    """The checks, the simulation and the map that ``options`` ask for of ``result``."""
    seed = planner_options.seed
    check = motion = arm = simulation = reach = None
    if options.verify and result.solved:
        from ..execution.verify import verify  # the re-simulator, loaded only for verify

        check = verify(scene, result, options.verify, seed, transit=planner_options.transit,
                       regions=planner_options.regions)
    # The arm's joints are checked wherever they are used: written, or followed in the simulation.
    if result.solved and (options.trajectory or (options.simulate and scene.robot is not None)):
        if scene.robot is None:
            from ..execution.trajectory import trajectory  # loads ruckig, only for a trajectory

            moved = trajectory(scene, result)
        else:
            from ..execution.arm_timing import arm_trajectory  # loads mink and MuJoCo, only for an arm

            moved, arm = arm_trajectory(scene, result)
        motion = moved if options.trajectory else None
    if options.simulate and result.solved:
        simulation = _simulated(scene, options, planner_options, result, session, None if arm is None else (moved, arm))
    if options.reach:  # the map is about the start, whatever the plan
        mapped = scene if options.part is None else scene.move_scene(options.part, scene.starts)
        if reach_map is None:
            from ..queries.reachable_set import reachable_set

            reach_map = reachable_set
        reach = reach_map(mapped, options.reach, regions=planner_options.regions, margin=planner_options.margin)
    return Outcome(scene, result, verification=check, simulation=simulation, trajectory=motion, arm=arm, reach=reach)


def _simulated(scene: Scene, options: RunOptions, planner_options: PlannerOptions, result: Plan,
               session: Planner | None, arm=None):
    """The MuJoCo runs of ``result`` (MuJoCo is loaded only now): open loop, the scene's arm (if
    any) following ``arm`` (the trajectory and the joints along it), or closed loop on
    ``session`` (made now, with ``planner_options``, for a plan read from a file), whose re-plans
    join ``result``."""
    seed, cf_offset = planner_options.seed, options.sim_cf_offset or (0.0, 0.0)
    start_error = options.start_error or (0.0, 0.0, 0.0)
    if not options.closed_loop:
        from ..execution.mujoco_sim import simulate

        return simulate(scene, result, options.simulate, seed, options.sim_mu, cf_offset, start_error, options.bumps,
                        arm)
    from ..execution.closed_loop import closed_loop

    if session is None:
        session = Planner(scene, planner_options)
        # A plan for the goal that re-plans are joined to; a tray's move sessions are made as its moves are tracked.
        if len(scene.parts) == 1:
            session.plan(start=result.start)
    return closed_loop(session, result, options.simulate, seed, options.sim_mu, cf_offset, start_error,
                       options.bumps, options.pose_noise or (0.0, 0.0), options.observe or "truth")


def check_outputs(options: RunOptions) -> None:
    """Refuse, before any work, outputs that cannot be written: ``out`` a file, or a folder (or
    the nearest one above it that exists) where no file can be made; likewise ``mjcf``'s folder
    where it lies outside ``out``; ``export_scene`` a folder.

    Raises
    ------
    SceneError
        Naming ``out`` or ``export_scene`` for a name that cannot be used.
    OutputError
        For a place where nothing can be written.
    """
    out = options.out
    try:
        taken = out.exists() and not out.is_dir()
    except (OSError, ValueError) as err:  # a name too long, or with a NUL
        raise SceneError("out", f"cannot use {shown(str(out))}: {getattr(err, 'strerror', None) or err}") from None
    if taken:
        raise SceneError("out", f"{shown(str(out))} exists and is not a folder")
    _check_writable(out, out)
    if options.mjcf is not None and _within(Path(options.mjcf), out, out) == Path(options.mjcf):
        _check_writable(Path(options.mjcf).parent, Path(options.mjcf))
    if options.export_scene is not None and Path(options.export_scene).is_dir():
        raise SceneError("export_scene", f"{shown(str(options.export_scene))} is a folder")


def _write(outcome: Outcome, options: RunOptions, planner_options: PlannerOptions,
           write_recording: Callable[..., None]) -> list[str]:
    """Write ``outcome``'s files into ``options.out`` (module docstring): the recording (with the
    verification's ghost, the map and the worst simulated run, or a closed loop's runs on their
    own clocks), the map's PNG, the trajectory's CSV (and a closed loop's executed paths), the
    first run's MJCF, the scene as planned (with ``planner_options``), and the plan file last.
    Returns the names written, the plan file first."""
    scene, out, name = outcome.scene, options.out, outcome.scene.name
    simulation, closed = outcome.simulation, options.closed_loop
    files = [f"{name}.json", f"{name}.rrd"]
    if options.export_scene is not None:
        try:
            from ..model.scene_file import write_scene

            write_scene(scene, options.export_scene, planner_options)
        except OSError as err:
            raise OutputError(f"cannot write {shown(str(options.export_scene))}: {err.strerror or err}") from None
    with _writing(out, name) as stage:
        write_recording(stage / f"{name}.rrd", scene, outcome.plan, outcome.verification, outcome.reach,
                        None if closed else simulation, simulation if closed else None)
        if outcome.trajectory is not None:
            outcome.trajectory.write_csv(stage / f"{name}.trajectory.csv")
            files.append(f"{name}.trajectory.csv")
            if outcome.arm is not None:
                outcome.arm.write_csv(stage / f"{name}.joints.csv")
                files.append(f"{name}.joints.csv")
            if closed and simulation is not None:
                simulation.write_executed(stage, name)
                executed = simulation.executed_files(name)
                files += executed[:1] + ([f"... {executed[-1]}"] if len(executed) > 1 else [])
        if outcome.reach is not None:
            from ..queries.reachable_set import write_png

            with atomic_path(stage / f"{name}-reach.png") as tmp:
                write_png(outcome.reach, scene if options.part is None else scene.move_scene(options.part, scene.starts),
                          str(tmp))
            files.append(f"{name}-reach.png")
        if simulation is not None and options.mjcf is not None:
            simulation.write_mjcf(_within(Path(options.mjcf), out, stage), scene)
        write_atomic(stage / f"{name}.json", outcome.plan.to_json())
    return files


@contextmanager
def _writing(out: Path, name: str) -> Iterator[Path]:
    """The folder to write ``out``'s files in (a new ``out`` appears whole); a file that cannot be
    written, or a failed recording ``<name>.rrd``, is an :class:`OutputError` naming the file as
    the user named it."""
    stage = out
    try:
        with staged_folder(out) as stage:
            yield stage
    except OSError as err:
        named = str(err.filename or out)
        if Path(named).parent == out.parent and Path(named).name.startswith(f".{out.name}."):
            named = str(out)  # the staged folder itself could not be made: the user named its target
        named = named.replace(str(stage), str(out), 1)  # a file as the user named it
        raise OutputError(f"cannot write {shown(named)}: {err.strerror or err}") from None
    except RecordingFailed as err:
        raise OutputError(f"cannot write {shown(str(out / f'{name}.rrd'))}: the recording failed: {err}") from None


def _check_writable(folder: Path, named: Path) -> None:
    """Raise :class:`OutputError` naming ``named`` unless a file can be made in ``folder`` or, if
    that does not exist yet, in the nearest folder above it that does (where it would be made).
    The test file is anonymous (``O_TMPFILE`` where there is one) and gone at once."""
    place = folder
    try:
        while not place.exists() and place != place.parent:
            place = place.parent
        with tempfile.TemporaryFile(dir=place):
            pass
    except (OSError, ValueError) as err:  # ValueError: a NUL in the name
        raise OutputError(f"cannot write {shown(str(named))}: {getattr(err, 'strerror', None) or err}") from None


def _within(path: Path, out: Path, stage: Path) -> Path:
    """``path``, or where it is written while ``out`` is staged if it lies in ``out``."""
    try:
        return stage / Path(path).resolve().relative_to(out.resolve())
    except ValueError:
        return Path(path)
