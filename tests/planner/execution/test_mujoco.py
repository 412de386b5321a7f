"""Whole plans run open-loop in MuJoCo (planner.execution.mujoco_sim, ``plan --simulate``).

The battery's seed-1 plan (one push) is run on a few support distributions: as planned it ends
within the scene's tolerance without slip or collision; with far less pusher friction than planned,
or the centre of pressure moved well off the CF, some run slips or misses the goal (exit 3), and
the recording shows that run's part where the printed line says it ended. A lift on its own
(narrow_junction's) leaves the part where it was. Without MuJoCo, ``--simulate`` is bad input
with one line saying how to install it. A plan of several parts runs through the same simulation:
its model (every part a body of its own) loads in MuJoCo, a start error moves the part moved first
and a bump the part the pusher is on.
"""

from __future__ import annotations

import math
import re
import subprocess
import sys
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest

from planner import load_scene, plan
from planner.cli import main
from planner.model.plan import Plan
from test_recording import rrd_rows

ROOT = Path(__file__).resolve().parents[3]
BATTERY = str(ROOT / "scenes" / "battery.yaml")


def test_without_mujoco_simulate_is_one_line_of_bad_input(tmp_path):
    """``import mujoco`` made to fail in a fresh interpreter: the line, exit 1, nothing written."""
    script = f"""
import sys
sys.modules["mujoco"] = None  # an import of it raises ImportError
from planner.cli import main
sys.exit(main([{BATTERY!r}, "--simulate", "2", "--out", {str(tmp_path / 'out')!r}]))
"""
    run = subprocess.run([sys.executable, "-c", script], capture_output=True, text=True, cwd=ROOT, timeout=120)
    assert run.returncode == 1
    assert run.stderr.strip() == "plan: error: --simulate: needs MuJoCo: pip install 'stablepush[mujoco]'"
    assert not (tmp_path / "out").exists()


mujoco = pytest.importorskip("mujoco", reason="MuJoCo is not installed: pip install 'stablepush[mujoco]'")


@pytest.fixture(scope="module")
def battery():
    scene = load_scene(BATTERY)
    return scene, plan(scene, seed=1)


def test_the_battery_plan_reaches_the_goal_in_mujoco(battery):
    from planner.execution.mujoco_sim import SLIP, simulate

    scene, result = battery
    simulation = simulate(scene, result, n=3, seed=1)
    assert [r.feet.kind for r in simulation.runs] == ["grid", "extreme", "random"]
    for run in simulation.runs:
        assert run.goal_error[0] <= scene.tolerance_position and run.goal_error[1] <= scene.tolerance_angle
        assert run.in_goal and run.slip <= SLIP and run.collisions == 0
        assert run.deviation < scene.tolerance_position
    assert simulation.passed


def test_every_foot_carries_its_share_of_the_weight_at_every_step_of_a_push(battery):
    """The support distribution is the one meant all along the battery's push (lead-in included),
    on a grid of feet and on an extreme tripod: at every step each foot's normal force on the table
    is within 2 % of its share of the weight (measured: 0.4 %). At Earth's gravity the soft contact
    lifted the sliding feet: each carried nothing in 7-10 % of the steps and up to 1.5 times its
    share in others."""
    import planner.execution.mujoco_sim as sim

    scene, result = battery
    setup = sim.perturbations(scene, result)
    led, follow = sim._follower(setup.lead), sim._follower(setup.motion)

    def pusher(u):
        return led(u) if u < setup.lead.duration else follow(u - setup.lead.duration)

    force = np.zeros(6)
    for supports in sim.foot_sets(scene, 2):
        world = sim.World(scene, supports, None, setup.starts)
        model, data = world.model, world.data
        feet = [model.geom(f"foot{k}").id for k in range(len(supports["part"].points))]
        share = supports["part"].weights * sim.MASS * sim.GRAVITY
        world.step_to(sim.SETTLE, pusher)  # the feet settle on the table
        loads = []
        while data.time < sim.SETTLE + setup.lead.duration + setup.motion.duration:
            world.step_to(data.time + sim.TIMESTEP, pusher)
            load = np.zeros(len(feet))
            for i, pair in enumerate(data.contact.geom[:data.ncon]):
                for k in np.flatnonzero(np.isin(feet, pair)):
                    mujoco.mj_contactForce(model, data, i, force)
                    load[k] += force[0]
            loads.append(load / share)
        assert np.abs(np.array(loads) - 1).max() < 0.02, supports["part"].kind


def test_plan_simulate_passes_and_writes_a_model_mujoco_reads(tmp_path, capsys):
    model = tmp_path / "battery.xml"
    code = main([BATTERY, "--simulate", "3", "--mjcf", str(model), "--trajectory", "--out", str(tmp_path / "out")])
    lines = capsys.readouterr().out.splitlines()
    assert code == 0
    assert [line.split(" (")[0] for line in lines[1:4]] == ["simulate 1/3", "simulate 2/3", "simulate 3/3"]
    assert lines[4].startswith("simulate: passed: 3/3 runs")
    loaded = mujoco.MjModel.from_xml_path(str(model))
    assert loaded.body("part").id > 0 and loaded.body("pusher").id > 0
    # The simulation's physics is the file's: a viewer steps the model the runs stepped.
    import planner.execution.mujoco_sim as sim

    assert loaded.opt.gravity[2] == -sim.GRAVITY and loaded.opt.noslip_iterations == sim.NOSLIP_ITERATIONS
    pusher_geom = loaded.geom("pusher").id
    pusher_pairs = [i for i in range(loaded.npair) if pusher_geom in (loaded.pair_geom1[i], loaded.pair_geom2[i])]
    assert pusher_pairs and all(loaded.pair_solref[i][0] == 2 * loaded.opt.timestep for i in pusher_pairs)
    # Keyframes along the run: the pusher where the trajectory has it at the key's time.
    csv = np.loadtxt(tmp_path / "out" / "battery.trajectory.csv", delimiter=",", skiprows=1)
    assert loaded.nkey == math.ceil(csv[-1, 0]) + 1 and loaded.key("start").time[0] == 0.0
    pusher = loaded.joint("pusher_x").qposadr[0] + np.array([0, 1, 2, 3])
    for k in range(loaded.nkey):
        time, qpos = loaded.key(k).time[0], loaded.key(k).qpos
        row = csv[np.argmin(np.abs(csv[:, 0] - time))]
        assert abs(row[0] - time) < 1e-9 and np.allclose(qpos[pusher], row[[1, 2, 7, 3]], atol=1e-9)


def pose_of(strip: np.ndarray, vertices: np.ndarray) -> np.ndarray:
    """The rigid pose that puts the part's ``vertices`` on the closed outline ``strip`` (least squares)."""
    drawn = np.asarray(strip, dtype=float)[:-1]
    a, b = vertices - vertices.mean(axis=0), drawn - drawn.mean(axis=0)
    theta = np.arctan2((a[:, 0] * b[:, 1] - a[:, 1] * b[:, 0]).sum(), (a * b).sum())
    c, s = np.cos(theta), np.sin(theta)
    origin = drawn.mean(axis=0) - np.array([[c, -s], [s, c]]) @ vertices.mean(axis=0)
    assert np.abs(drawn - (origin + vertices @ np.array([[c, s], [-s, c]]))).max() < 1e-6  # a rigid copy (rerun keeps float32)
    return np.array([*origin, theta])


@pytest.mark.parametrize("flags", [["--sim-mu", "0.01"], ["--sim-cf-offset", "0", "-0.012"]],
                         ids=["friction-far-below-plan", "centre-of-pressure-off-the-cf"])
def test_a_plan_simulated_outside_its_assumptions_fails(tmp_path, capsys, flags):
    code = main([BATTERY, "--simulate", "3", "--out", str(tmp_path / "out"), *flags])
    out = capsys.readouterr().out
    assert code == 3
    assert "simulate: FAILED" in out and ("SLIPS" in out or "misses the goal" in out)
    assert (tmp_path / "out" / "battery.json").is_file()
    # The recording shows the run straying farthest, ending where its line says it ended.
    runs = [(float(d), float(e)) for e, d in re.findall(r"from the plan's end ([\d.e+-]+) m.*?path deviation ([\d.e+-]+) m",
                                                      out)]
    _, ended = max(runs)
    rrd = tmp_path / "out" / "battery.rrd"
    shown = [strip for _, (strip,) in rrd_rows(rrd, "/world/simulated", "LineStrips3D:strips", "step")]
    planned = [strip for _, (strip,) in rrd_rows(rrd, "/world/slider", "LineStrips3D:strips", "step")]
    assert len(shown) == len(planned) > 2
    vertices = load_scene(BATTERY).slider.vertices
    start, first = pose_of(planned[0], vertices), pose_of(shown[0], vertices)
    assert np.abs(first - start).max() < 1e-3  # both start at the start: the part settled on its feet
    gap = np.linalg.norm(pose_of(shown[-1], vertices)[:2] - pose_of(planned[-1], vertices)[:2])
    assert gap == pytest.approx(ended, rel=0.01)
    (_, summary), = rrd_rows(rrd, "/log/simulate", "TextLog:text")
    assert summary[0].startswith("simulate: FAILED")


def test_a_lift_alone_leaves_the_part_where_it_is():
    """The pusher rises straight off the part and lands beside it: the part does not move. (Rising
    while turning once swung the face's ends into it: 1.7 mm and 1.5 degrees.)"""
    from planner.execution.mujoco_sim import simulate

    scene = load_scene(ROOT / "scenes" / "narrow_junction.yaml")
    result = plan(scene, seed=1)
    lift = next(s for s in result.segments if s.kind == "transit" and s.mode == "lift")
    alone = Plan.of_part("part", lift.pose, lift.pose, [lift],
                         scene=None, solved=True, planner="rrt", seed=1, planning_time_s=0.0)
    (run,) = simulate(scene, alone, n=1).runs
    assert run.collisions == 0 and run.final_error[0] < 5e-5 and run.final_error[1] < 1e-3
    assert run.deviation < 5e-5


@pytest.mark.parametrize("argv, field", [(["--sim-mu", "0.5"], "--sim-mu"), (["--simulate", "0"], "--simulate"),
                                         (["--simulate", "1", "--sim-cf-offset", "1", "0"], "--sim-cf-offset"),
                                         # Physical ranges: beyond them the state blows up or means nothing.
                                         (["--simulate", "1", "--sim-mu", "1e300"], "--sim-mu"),
                                         (["--simulate", "1", "--sim-bump", "1", "0", "0", "1e20"], "--sim-bump"),
                                         (["--simulate", "1", "--sim-start-error", "0", "0", "200"], "--sim-start-error"),
                                         (["--simulate", "1", "--closed-loop", "--sim-pose-noise", "1e6", "0"],
                                          "--sim-pose-noise")])
def test_bad_simulation_flags_are_bad_input(tmp_path, capsys, argv, field):
    assert main([BATTERY, "--out", str(tmp_path / "out"), *argv]) == 1
    assert capsys.readouterr().err.startswith(f"plan: error: {field}: ")
    assert not (tmp_path / "out").exists()


#: Where a push of each part's edge is studied (far from walls and obstacles): scene, index into
#: its pushable edges, start pose.
OPEN_PUSHES = [("battery", 0, (0.0, 0.0, 0.0)), ("parking", 0, (-0.3, 0.2, 0.0)), ("corridor", 0, (0.0, -0.45, 0.0))]


@pytest.mark.parametrize("name, which, start", OPEN_PUSHES, ids=[name for name, _, _ in OPEN_PUSHES])
def test_pushes_inside_the_exact_region_stick_and_pushes_outside_slip_in_mujoco(monkeypatch, name, which, start):
    """An edge of the battery, parking's part and corridor's, six vertices of its exact region
    beyond STABLE's: the twist 5 % closer to the region's centre and the one 10 % farther out,
    each pushed 6 cm (the part's fastest point) from an open spot. The independent LP
    (tests/oracle.py, no ``mechanics`` code) finds each twist's worst support distribution, two
    or three feet on the part's rim. Slip is the pusher face's motion in the part frame over the
    push: the inside twist stays under 0.1 mm on both twists' worst distributions and on the
    simulator's own foot sets (measured 0.02-0.07 mm, the soft contact's creep); on its worst
    distribution the outside twist slips past 0.5 mm and ten times as far as the inside one on the
    same feet. Measured over every vertex beyond STABLE's, the outside twists slip 0.89-4.4 mm on
    the battery, 1.4-13 mm on parking and 0.90-10 mm on corridor: under 1 mm only near a few
    vertices of the battery's and corridor's regions. The outside twists do not slip on a grid
    of feet: only some distributions break them, which is what the region guards against."""
    import shapely
    from scipy.optimize import linprog

    import oracle as O
    import planner.execution.mujoco_sim as sim
    from mechanics import exact_region
    from planner.model.segments import Push

    scene = load_scene(ROOT / "scenes" / f"{name}.yaml")
    slider, pusher = scene.slider, scene.pusher
    edge = scene.edges[which]
    region = exact_region(slider, edge, pusher.mu, pusher.width)
    polygon, centre = region.section()
    ring = np.asarray(polygon.exterior.coords)[:-1]
    beyond = ring[~region.stable.contains(region.plane.twists(ring))]
    rim = shapely.get_coordinates(shapely.line_interpolate_point(
        shapely.Polygon(slider.vertices).exterior, np.linspace(0, 1, 96, endpoint=False), normalized=True))
    lp = O.LPOracle(O.Reference(slider.vertices, slider.cf, edge, pusher.mu, pusher.width),
                    np.vstack([O.support_samples(slider.vertices, 24), rim]))

    def worst_feet(twist):
        """The LP's worst distribution for ``twist`` and by how much it breaks sticking (> 0) or not."""
        g = lp.wrenches(twist)
        runs = [linprog(-(g @ a), A_eq=lp.A_eq, b_eq=lp.b_eq, bounds=(0, None), method="highs") for a in lp.facets]
        best = min(runs, key=lambda res: res.fun)
        on = best.x > 1e-9
        return sim.Feet("worst", lp.x[on], best.x[on] / best.x[on].sum(), slider.cf), -best.fun

    def slips(twist, feet):
        speed = max(math.hypot(*twist[:2]), abs(twist[2]) * slider.radius)
        push = Push.along(edge, region.contact, twist, 0.06 / speed, start)
        one = Plan.of_part("part", start, push.end, [push],
                           scene=None, solved=True, planner="rrt", seed=1, planning_time_s=0.0)
        monkeypatch.setattr(sim, "feet", lambda *args, **kwargs: feet)
        runs = sim.simulate(scene, one, n=len(feet)).runs
        assert not any(run.collisions for run in runs)
        return np.array([run.slip for run in runs])

    own = sim.feet(scene, 3, seed=1)
    for vertex in beyond[np.linspace(0, len(beyond), 6, endpoint=False).astype(int)]:
        inside, outside = region.plane.twists(centre + np.array([[0.95], [1.10]]) * (vertex - centre))
        assert region.contains(inside) and not region.contains(outside)
        (worst_in, holds), (worst_out, breaks) = worst_feet(inside), worst_feet(outside)
        assert holds <= 1e-9 < breaks  # the LP agrees: every distribution sticks inside, not outside
        stuck = slips(inside, [worst_out, worst_in, *own])
        slipped = slips(outside, [worst_out])[0]
        assert stuck.max() < 1e-4, (vertex, stuck)
        assert slipped > max(5e-4, 10 * stuck[0]), (vertex, stuck, slipped)


CHANNEL = str(ROOT / "scenes" / "parts" / "channel.yaml")


@pytest.fixture(scope="module")
def channel():
    from planner import Planner

    scene = load_scene(CHANNEL)
    return scene, Planner(scene, {"seed": 1, "time_limit": 60}).plan()


def test_one_part_and_several_run_through_the_same_simulation_and_a_tray_model_loads(tmp_path, monkeypatch, channel):
    """``plan --simulate`` calls the one :func:`simulate` for a scene of one part and of several;
    the channel's ``--mjcf`` model loads, every part a body of its own, with keyframes of the planned
    parts and the pusher along the run."""
    import planner.execution.mujoco_sim as sim

    scene, result = channel
    calls, real = [], sim.simulate
    monkeypatch.setattr(sim, "simulate", lambda scene, plan, *args: calls.append(len(scene.parts)) or real(scene, plan, *args))
    assert main([BATTERY, "--simulate", "1", "--out", str(tmp_path / "one")]) == 0
    (tmp_path / "channel.json").write_text(result.to_json())
    model = tmp_path / "channel.xml"
    assert main([CHANNEL, "--plan", str(tmp_path / "channel.json"), "--simulate", "1", "--mjcf", str(model),
                 "--trajectory", "--out", str(tmp_path / "two")]) == 0
    assert calls == [1, 2]
    loaded = mujoco.MjModel.from_xml_path(str(model))
    assert loaded.body("part0").id > 0 and loaded.body("part1").id > 0 and loaded.body("pusher").id > 0
    csv = np.loadtxt(tmp_path / "two" / "channel.trajectory.csv", delimiter=",", skiprows=1, usecols=range(10))
    assert loaded.nkey == math.ceil(csv[-1, 0]) + 1
    parts = {name: loaded.joint(f"part{k}_x").qposadr[0] + np.arange(3) for k, name in enumerate(scene.names)}
    pusher = loaded.joint("pusher_x").qposadr[0] + np.arange(4)
    first, last = loaded.key("start").qpos, loaded.key(loaded.nkey - 1).qpos
    for name, slots in parts.items():
        assert np.allclose(first[slots], scene.starts[name]) and np.allclose(last[slots], result.finals[name], atol=1e-9)
    for k in range(loaded.nkey):
        time, qpos = loaded.key(k).time[0], loaded.key(k).qpos
        row = csv[np.argmin(np.abs(csv[:, 0] - time))]
        assert abs(row[0] - time) < 1e-9 and np.allclose(qpos[pusher], row[[1, 2, 7, 3]], atol=1e-9)


def test_the_tray_model_has_every_part_on_its_feet_and_every_contact_that_tells():
    """Every part of the tray a body at its start on its own feet; contacts of the pusher with every
    part, and of every part with every other part and with the walls."""
    from planner.execution.mujoco_sim import feet, mjcf

    scene = load_scene(ROOT / "scenes" / "parts" / "tray.yaml")
    supports = {name: feet(scene.move_scene(name, scene.starts), 1)[0] for name in scene.names}
    model = mujoco.MjModel.from_xml_string(mjcf(scene, supports))
    data = mujoco.MjData(model)
    mujoco.mj_resetDataKeyframe(model, data, model.key("start").id)
    bodies = [model.body(model.geom_bodyid[g]).name for g in range(model.ngeom)]  # walls: the world's
    pairs = {frozenset((bodies[model.pair_geom1[i]], bodies[model.pair_geom2[i]])) for i in range(model.npair)}
    for k, name in enumerate(scene.names):
        assert np.allclose(data.qpos[model.joint(f"part{k}_x").qposadr[0] + np.arange(3)], scene.starts[name])
        assert sum(model.body(b).name.startswith(f"foot{k}_") for b in range(model.nbody)) == len(supports[name].points)
        assert {frozenset((f"part{k}", "pusher")), frozenset((f"part{k}", "world"))} <= pairs
        assert all(frozenset((f"part{k}", f"part{j}")) in pairs for j in range(k + 1, len(scene.parts)))


def test_a_start_error_moves_the_part_moved_first_and_a_bump_the_part_the_pusher_is_on(channel):
    """On the channel, far goes first: a start error moves far alone, a bump during near's move knocks
    near; one that would put a part onto the other is bad input naming the flag, and the run knocks
    the part the bump names."""
    from planner.execution.mujoco_sim import perturbations, simulate
    from planner.model.fields import SceneError
    from planner.model.plan import Move

    scene, result = channel
    first, then = (m.part for m in result.moves)
    setup = perturbations(scene, result, start_error=(0.0, 0.01, 0.0))
    assert np.allclose(setup.starts[first], result.starts[first] + [0.0, 0.01, 0.0])
    assert np.array_equal(setup.starts[then], result.starts[then])
    later = setup.lead.duration + setup.motion.t[np.flatnonzero(setup.motion.part == then)[0]] + 1.0
    assert [b[1] for b in perturbations(scene, result, bumps=[(0.0, 0.0, 0.001, 0.0), (later, 0.0, 0.001, 0.0)]).bumps] \
        == [first, then]
    onto = (result.starts[then] - result.starts[first])[:2]  # far's start onto near's
    for field, kwargs in (("start_error", {"start_error": (*onto, 0.0)}), ("bump", {"bumps": [(0.0, *onto, 0.0)]})):
        with pytest.raises(SceneError) as err:
            perturbations(scene, result, **kwargs)
        assert err.value.field == field and "cannot be" in err.value.problem
    # The first push alone, far knocked 3 mm sideways as the pusher sets off: far is where the knock put it.
    push = result.moves[0].segments[0]
    short = replace(result, moves=[Move(first, [push])])
    (run,) = simulate(scene, short, n=1, bumps=[(0.0, 0.0, 0.003, 0.0)]).runs
    assert run.tracks[first][0][1] == pytest.approx(result.starts[first][1] + 0.003, abs=5e-4)
    assert np.abs(run.tracks[then][-1] - result.starts[then]).max() < 1e-4


# A scene nobody tuned (drawn at random: a triangle, its CF off the centroid, mu 0.51), where the
# plan at the exact limit keeps only 6 % of the friction on one push.
UNTUNED = """\
name: untuned
slider:
  vertices: [[-0.0209, -0.0175], [0.003, 0.0261], [0.0182, 0.0098]]
  cf: [-0.0016, 0.0075]
pusher: {width: 0.057, depth: 0.01, mu: 0.51}
obstacles: [{box: {center: [0.2, -0.25], size: [0.06, 0.25], angle: 0}}]
workspace: {min: [-0.2, -0.45], max: [0.7, 0.45]}
start: [0, 0, 0]
goal: [0.32613, -0.07392, -18.8517]
"""


def test_a_plan_at_the_exact_limit_slips_with_less_friction_and_one_with_the_margin_does_not(tmp_path):
    """What the margin buys, in MuJoCo: with the pusher friction 10 % below the scene's, the plan
    made at the exact limit (whose certified friction margin says it keeps less than 10 %) slips
    on every run, and the plan made with the default margin sticks on every run."""
    from planner import Planner
    from planner.actions.margins import smallest, with_margins
    from planner.execution.mujoco_sim import SLIP, simulate
    from planner.model.scene_file import parse_scene
    import yaml

    scene = parse_scene(yaml.safe_load(UNTUNED))
    low = 0.9 * scene.pusher.mu
    exact = with_margins(scene, Planner(scene, {"seed": 1, "margin": 0}).plan())
    kept = with_margins(scene, Planner(scene, {"seed": 1}).plan())
    assert smallest(exact).mu < 0.1 <= smallest(kept).mu
    slipped = simulate(scene, exact, n=2, mu=low).runs
    held = simulate(scene, kept, n=2, mu=low).runs
    assert all(r.slip > SLIP and not r.passed for r in slipped), [r.slip for r in slipped]
    assert all(r.passed and r.slip < SLIP for r in held), [r.slip for r in held]


def test_a_run_that_blows_up_fails_at_once_saying_so_and_prints_nothing_of_mujoco(capfd):
    """A friction of 1e300 (the library takes what the command refuses) makes MuJoCo's state
    non-finite: each run, open or closed loop, stops there and fails with that reason, instead of
    stepping on for ever through MuJoCo's resets, and MuJoCo's own warnings are not printed."""
    from planner.execution.mujoco_sim import DIVERGED, simulate

    scene = load_scene(BATTERY)
    result = plan(scene, seed=1)
    runs = simulate(scene, result, n=2, mu=1e300).runs
    assert all(not r.passed and r.faults[0][1].startswith(DIVERGED) for r in runs)
    assert all(r.line(1, 1).endswith(r.faults[0][1]) for r in runs)
    from planner import Planner
    from planner.execution.closed_loop import closed_loop

    session = Planner(scene)
    (closed,) = closed_loop(session, session.plan(), 1, 1, 1e300).runs
    assert not closed.passed and closed.reason.startswith(DIVERGED)
    out, err = capfd.readouterr()
    assert "WARNING" not in out + err
