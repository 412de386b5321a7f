"""Issue 30: parts and obstacles from CAD files (planner.model.cad), against shapes whose area and
centroid are known in closed form, and the bad files of the issue refused in one line.

Sources of truth: closed forms (a rounded rectangle is its inner box grown by the radius, so a
point's distance to its boundary is ``|distance to the box - r|``; a regular polygon's area; the
centroid of a plate less a hole), a dense sampling of a Bézier by its Bernstein form, and the
files written here by the libraries' writers or by hand.
"""

from __future__ import annotations

import math
import re
import resource
import subprocess
import sys
import time
import tracemalloc
from pathlib import Path

import numpy as np
import pytest
import shapely
import yaml

ezdxf = pytest.importorskip("ezdxf")
pytest.importorskip("svgelements")
trimesh = pytest.importorskip("trimesh")

from planner.cli import main  # noqa: E402 (after the skips)
from planner.model.cad import MAX_FILE_BYTES, MAX_VERTICES  # noqa: E402
from planner.model.fields import SceneError  # noqa: E402
from planner.model.scene_file import load_scene, parse_scene  # noqa: E402
from test_cli import PLAN, assert_nothing_written, error_field  # noqa: E402

ROOT = Path(__file__).resolve().parents[3]
PUSHER = {"width": 0.03, "depth": 0.01, "mu": 0.5}
#: A rounded rectangle in mm: w x h, corners of radius r, and a hole of radius a at (hx, hy).
W, H, R, A, HX, HY = 80.0, 50.0, 8.0, 6.0, 20.0, 5.0


def scene(slider, obstacles=(), **changes) -> dict:
    return {"slider": slider, "pusher": PUSHER, "obstacles": list(obstacles),
            "workspace": {"min": [-1, -1], "max": [1, 1]}, "start": [-0.5, -0.5, 0], "goal": [0.5, 0.5, 0], **changes}


def load(folder: Path, data: dict):
    path = folder / "scene.yaml"
    path.write_text(yaml.safe_dump(data))
    return load_scene(path)


def rounded_rectangle(msp, layer: str = "PART", centre=(0.0, 0.0), hole: bool = True) -> None:
    """The rounded rectangle as one LWPOLYLINE with a quarter-circle bulge at each corner, and its hole."""
    b, (cx, cy) = math.tan(math.pi / 8), centre
    corners = [(-W / 2 + R, -H / 2, 0), (W / 2 - R, -H / 2, b), (W / 2, -H / 2 + R, 0), (W / 2, H / 2 - R, b),
               (W / 2 - R, H / 2, 0), (-W / 2 + R, H / 2, b), (-W / 2, H / 2 - R, 0), (-W / 2, -H / 2 + R, b)]
    msp.add_lwpolyline([(x + cx, y + cy, bulge) for x, y, bulge in corners], format="xyb", close=True,
                       dxfattribs={"layer": layer})
    if hole:
        msp.add_circle((HX + cx, HY + cy), A, dxfattribs={"layer": layer})


def dxf_file(folder: Path, draw, name: str = "part.dxf") -> Path:
    doc = ezdxf.new()
    draw(doc.modelspace())
    doc.saveas(folder / name)
    return folder / name


def svg_file(folder: Path, body: str, name: str = "part.svg") -> Path:
    (folder / name).write_text(f'<svg xmlns="http://www.w3.org/2000/svg" viewBox="0 0 200 200">{body}</svg>')
    return folder / name


# --- closed forms ------------------------------------------------------------------------------------

def test_bulged_rounded_rectangle_with_a_hole_has_its_closed_form_area_and_cf(tmp_path):
    dxf_file(tmp_path, rounded_rectangle)
    part = load(tmp_path, scene({"file": "part.dxf", "units": "mm"})).slider
    outline = W * H - (4 - math.pi) * R ** 2  # mm^2
    footprint = outline - math.pi * A ** 2
    cf = -math.pi * A ** 2 * np.array([HX, HY]) / footprint  # the plate's centroid is its centre
    assert part.area * 1e6 == pytest.approx(outline, rel=0.005)
    assert np.abs(part.cf * 1e3 - cf).max() < 0.05
    inner = shapely.box(-(W / 2 - R), -(H / 2 - R), W / 2 - R, H / 2 - R)
    off = [abs(inner.distance(shapely.Point(v)) - R) for v in part.vertices * 1e3]
    assert max(off) <= 0.1 + 1e-9  # every vertex within the chord tolerance of the drawn curve
    assert len(part.vertices) < 60  # and simplified: the straight sides are one edge each


def test_the_chord_tolerance_is_settable(tmp_path):
    dxf_file(tmp_path, rounded_rectangle)
    coarse = load(tmp_path, scene({"file": "part.dxf", "units": "mm", "chord": 0.002})).slider
    fine = load(tmp_path, scene({"file": "part.dxf", "units": "mm", "chord": 0.00001})).slider
    inner = shapely.box(-(W / 2 - R), -(H / 2 - R), W / 2 - R, H / 2 - R)
    for part, chord in ((coarse, 2.0), (fine, 0.01)):
        assert max(abs(inner.distance(shapely.Point(v)) - R) for v in part.vertices * 1e3) <= chord + 1e-9
    assert len(coarse.vertices) < len(fine.vertices)


@pytest.mark.parametrize("kind", ["ELLIPSE", "POLYLINE", "SPLINE"])
def test_ellipses_polylines_and_splines_are_outlines(kind, tmp_path):
    def draw(msp):
        if kind == "ELLIPSE":  # semi-axes 30 and 12 mm
            msp.add_ellipse((0, 0), major_axis=(30, 0), ratio=0.4)
        elif kind == "POLYLINE":  # two half circles of radius 20 mm: bulge 1 each
            msp.add_polyline2d([(-20, 0, 0, 0, 1), (20, 0, 0, 0, 1)], format="xyseb", close=True)
        else:  # a spline through points round a square, ending where it starts
            msp.add_spline([(-20, -20), (20, -20), (20, 20), (-20, 20), (-20, -20)])

    dxf_file(tmp_path, draw)
    part = load(tmp_path, scene({"file": "part.dxf", "units": "mm"})).slider
    if kind == "ELLIPSE":
        assert math.pi * (30 - 0.1) * (12 - 0.1) < part.area * 1e6 < math.pi * 30 * 12
    elif kind == "POLYLINE":
        assert math.pi * (20 - 0.1) ** 2 < part.area * 1e6 < math.pi * 20 ** 2
    else:
        assert part.area * 1e6 > 0.5 * 40 * 40  # a loop round the square, not a sliver
        return  # a spline through points need not be symmetric
    assert part.cf == pytest.approx([0, 0], abs=5e-5)


def test_svg_outline_with_a_cubic_side_has_the_area_of_a_dense_reference(tmp_path):
    controls = np.array([[60, 10], [90, 20], [90, 40], [60, 50]], float)
    svg_file(tmp_path, '<path d="M 10 10 L 60 10 C 90 20 90 40 60 50 L 10 50 Z"/>')
    part = load(tmp_path, scene({"file": "part.svg", "units": "mm"})).slider
    t = np.linspace(0, 1, 100_001)[:, None]
    bezier = (1 - t) ** 3 * controls[0] + 3 * (1 - t) ** 2 * t * controls[1] + 3 * (1 - t) * t ** 2 * controls[2] \
        + t ** 3 * controls[3]
    reference = shapely.Polygon(np.vstack([[10, 10], bezier, [10, 50]])).area
    assert part.area * 1e6 == pytest.approx(reference, rel=0.01)
    # y flipped: the drawing's top (y = 10 down the screen) is the part's top on the table (y = -10 mm)
    assert part.polygon.bounds == pytest.approx((0.01, -0.05, 0.01 + 0.0725, -0.01), abs=2e-4)


def prism(ring: list, height: float):
    """The prism over the convex polygon ``ring`` (counter-clockwise), each face a fan of triangles."""
    n = len(ring)
    vertices = [(x, y, 0.0) for x, y in ring] + [(x, y, height) for x, y in ring]
    faces = [(0, k + 1, k) for k in range(1, n - 1)] + [(n, n + k, n + k + 1) for k in range(1, n - 1)]
    faces += [face for k in range(n) for face in ((k, (k + 1) % n, n + (k + 1) % n), (k, n + (k + 1) % n, n + k))]
    return trimesh.Trimesh(vertices, faces)


def test_stl_prism_footprint_has_the_area_of_its_regular_polygon(tmp_path):
    n, radius = 12, 30.0
    ring = [(radius * math.cos(2 * math.pi * k / n), radius * math.sin(2 * math.pi * k / n)) for k in range(n)]
    prism(ring, 15.0).export(tmp_path / "prism.stl")
    part = load(tmp_path, scene({"file": "prism.stl", "units": "mm"})).slider
    assert part.area * 1e6 == pytest.approx(n / 2 * radius ** 2 * math.sin(2 * math.pi / n), rel=0.005)
    assert len(part.vertices) == n


def test_a_mesh_outline_is_its_projection_and_its_cf_the_footprints_centroid(tmp_path):
    # A narrow foot (20 x 20 mm, centred at 30, 0) under a wide top (60 x 40 mm, centred at 0, 0).
    foot = trimesh.creation.box((20, 20, 10)).apply_translation((30, 0, 5))
    top = trimesh.creation.box((60, 40, 10)).apply_translation((0, 0, 15))
    trimesh.util.concatenate([foot, top]).export(tmp_path / "mushroom.stl")
    part = load(tmp_path, scene({"file": "mushroom.stl", "units": "mm"})).slider
    assert part.polygon.bounds == pytest.approx((-0.03, -0.02, 0.04, 0.02), abs=1e-7)  # the union of both
    assert part.area == pytest.approx(60 * 40e-6 + 10 * 20e-6, rel=1e-4)
    assert part.cf == pytest.approx([0.03, 0.0], abs=1e-7)


def plate_with_a_hole(outer: float, hole: float, hole_x: float, height: float):
    """A square plate ``outer`` mm wide with a square hole ``hole`` mm wide centred at (``hole_x``,
    0), as one mesh whose top and bottom faces are each one patch with a hole (trimesh's own
    projection needed networkx and rtree, which the cad extra does not install, for those)."""
    o = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * outer / 2
    i = np.array([[-1, -1], [1, -1], [1, 1], [-1, 1]]) * hole / 2 + [hole_x, 0]
    vertices = np.vstack([np.c_[ring, np.full(4, z)] for z in (0.0, height) for ring in (o, i)])  # O0 I0 O1 I1
    ring = [(k, (k + 1) % 4) for k in range(4)]
    top = [f for a, b in ring for f in ((8 + a, 8 + b, 12 + b), (8 + a, 12 + b, 12 + a))]
    bottom = [f[::-1] for f in [(a, b, 4 + b) for a, b in ring] + [(a, 4 + b, 4 + a) for a, b in ring]]
    walls = [f for a, b in ring for f in ((a, b, 8 + b), (a, 8 + b, 8 + a))]
    walls += [f[::-1] for a, b in ring for f in ((4 + a, 4 + b, 12 + b), (4 + a, 12 + b, 12 + a))]
    return trimesh.Trimesh(vertices, top + bottom + walls, process=False)


def test_a_mesh_whose_faces_have_holes_is_read_and_its_cf_leaves_the_hole(tmp_path, monkeypatch, capsys):
    """Issue 41's fuzzing: a washer or a plate with a bolt hole as an STL ended in a traceback
    (ModuleNotFoundError: networkx). Its outline is the plate's; its CF is the footprint's
    centroid, moved away from the hole: -(10 * 10 * 10) / (40 * 40 - 10 * 10) mm."""
    plate_with_a_hole(40, 10, 10, 5).export(tmp_path / "plate.stl")
    part = load(tmp_path, scene({"file": "plate.stl", "units": "mm"})).slider
    assert part.polygon.bounds == pytest.approx((-0.02, -0.02, 0.02, 0.02))
    assert part.cf == pytest.approx([-1000 / 1500 * 1e-3, 0], abs=1e-9)
    (tmp_path / "scene.yaml").write_text(yaml.safe_dump(scene({"file": "plate.stl", "units": "mm"},
                                                              start=[0, 0, 0], goal=[0.3, 0, 0])))
    monkeypatch.chdir(tmp_path)
    assert main(["scene.yaml", "--out", "out"]) == 0
    assert capsys.readouterr().out.startswith("solved: ")


# --- selection, units, placement --------------------------------------------------------------------

def two_parts(msp) -> None:
    rounded_rectangle(msp, "PART")
    rounded_rectangle(msp, "SPARE", centre=(200.0, 0.0), hole=False)


def test_a_layer_picks_one_part_of_several(tmp_path, monkeypatch, capsys):
    dxf_file(tmp_path, two_parts)
    spare = load(tmp_path, scene({"file": "part.dxf", "units": "mm", "layer": "spare"})).slider
    assert spare.polygon.bounds == pytest.approx((0.16, -0.025, 0.24, 0.025), abs=1e-4)  # within the chord
    assert spare.cf == pytest.approx([0.2, 0.0], abs=5e-5)  # no hole on that layer
    part = load(tmp_path, scene({"file": "part.dxf", "units": "mm", "layer": "PART"})).slider
    assert part.polygon.bounds == pytest.approx((-0.04, -0.025, 0.04, 0.025), abs=1e-4)
    with pytest.raises(SceneError, match="slider.file: holds 2 parts: pick one with layer or object"):
        load(tmp_path, scene({"file": "part.dxf", "units": "mm"}))


def test_a_block_name_picks_its_drawing(tmp_path):
    doc = ezdxf.new()
    rounded_rectangle(doc.blocks.new("BRACKET"), "0", hole=False)
    doc.modelspace().add_blockref("BRACKET", (100, 100))
    doc.saveas(tmp_path / "part.dxf")
    assert load(tmp_path, scene({"file": "part.dxf", "units": "mm", "name": "BRACKET"})).slider.cf == \
        pytest.approx([0, 0], abs=5e-5)  # the block's own frame
    placed = load(tmp_path, scene({"file": "part.dxf", "units": "mm"}),).slider  # the reference, expanded
    assert placed.cf == pytest.approx([0.1, 0.1], abs=5e-5)


INKSCAPE = 'xmlns:inkscape="http://www.inkscape.org/namespaces/inkscape"'


def test_an_svg_layer_or_element_id_picks_one_part(tmp_path):
    (tmp_path / "part.svg").write_text(
        f'<svg xmlns="http://www.w3.org/2000/svg" {INKSCAPE} viewBox="0 0 200 200">'
        '<g inkscape:groupmode="layer" inkscape:label="Parts" transform="translate(100, 0)">'
        '<rect id="small" x="0" y="0" width="10" height="10"/><g id="big"><rect x="0" y="50" width="40" height="20"/>'
        '</g></g><g inkscape:groupmode="layer" inkscape:label="Guides"><circle cx="20" cy="20" r="5"/></g></svg>')
    guide = load(tmp_path, scene({"file": "part.svg", "units": "mm", "layer": "Guides"})).slider
    assert guide.cf == pytest.approx([0.02, -0.02], abs=1e-6)
    small = load(tmp_path, scene({"file": "part.svg", "units": "mm", "name": "small"})).slider
    assert small.polygon.bounds == pytest.approx((0.1, -0.01, 0.11, 0.0))  # the layer's transform applied
    big = load(tmp_path, scene({"file": "part.svg", "units": "mm", "name": "big"})).slider
    assert big.polygon.bounds == pytest.approx((0.1, -0.07, 0.14, -0.05))
    with pytest.raises(SceneError, match="holds 2 parts"):
        load(tmp_path, scene({"file": "part.svg", "units": "mm", "layer": "Parts"}))
    with pytest.raises(SceneError, match=r"no layer labelled 'Cut' \(layers: 'Guides', 'Parts'\)"):
        load(tmp_path, scene({"file": "part.svg", "units": "mm", "layer": "Cut"}))


def test_at_places_the_files_frame_in_the_slider_frame(tmp_path):
    svg_file(tmp_path, '<rect x="10" y="-30" width="20" height="10"/>')  # x 10..30, y 20..30 mm
    part = load(tmp_path, scene({"file": "part.svg", "units": "mm", "at": [-0.02, -0.025, 0], "cf": [0.0, 0.001]}))
    assert part.slider.polygon.bounds == pytest.approx((-0.01, -0.005, 0.01, 0.005))
    assert part.slider.cf.tolist() == [0.0, 0.001]  # a cf given is in the slider frame, as always


@pytest.mark.parametrize("units, metres", [("mm", 1e-3), ("cm", 1e-2), ("m", 1.0), ("in", 0.0254)])
def test_units_scale_the_drawing(units, metres, tmp_path):
    svg_file(tmp_path, '<rect x="1" y="2" width="3" height="0.5"/>')
    part = load(tmp_path, scene({"file": "part.svg", "units": units}, start=[0, 0, 0],
                                workspace={"min": [-10, -10], "max": [10, 10]}, goal=[1, 0, 0])).slider
    assert part.polygon.bounds == pytest.approx((metres, -2.5 * metres, 4 * metres, -2 * metres))


def test_at_places_the_files_frame_in_the_world(tmp_path):
    svg_file(tmp_path, '<rect x="10" y="-30" width="20" height="10"/>')  # x 10..30, y 20..30 mm on the table
    obstacles = load(tmp_path, scene(
        {"vertices": [[0, 0], [0.01, 0], [0, 0.01]]}, [{"file": "part.svg", "units": "mm", "at": [0.2, 0.1, 90]}])
    ).obstacles
    # Turned a quarter turn: (x, y) -> (-y, x), then moved by (0.2, 0.1).
    assert obstacles[0].bounds == pytest.approx((0.2 - 0.03, 0.1 + 0.01, 0.2 - 0.02, 0.1 + 0.03))


def test_every_closed_outline_is_an_obstacle_and_holes_are_left_open(tmp_path):
    svg_file(tmp_path, '<path d="M 0 0 L 100 0 L 100 100 L 0 100 Z M 20 20 L 80 20 L 80 80 L 20 80 Z"/>'
                       '<circle cx="150" cy="150" r="10"/><path d="M 0 150 L 20 150"/>')
    data = scene({"vertices": [[0, 0], [0.01, 0], [0, 0.01]]}, [{"file": "part.svg", "units": "mm"}],
                 start=[0.045, -0.055, 0], goal=[0.5, 0.5, 0])
    loaded = load(tmp_path, data)  # the part's start lies in the frame's hole
    frame = [o for o in loaded.obstacles if o.bounds[2] < 0.12]
    assert all(not o.interiors for o in loaded.obstacles)
    assert sum(o.area for o in frame) == pytest.approx((100 ** 2 - 60 ** 2) * 1e-6)
    post = [o for o in loaded.obstacles if o.bounds[0] > 0.1]
    assert len(post) == 1 and math.pi * (0.01 - 1e-4) ** 2 < post[0].area < math.pi * 0.01 ** 2  # within the chord
    assert loaded.notes == ("obstacles[0].file: 1 open subpath(s) are not read",)


def test_line_chains_that_close_are_outlines_and_open_ones_a_note(tmp_path):
    def chain(msp):
        msp.add_line((0, 0), (40, 0))
        msp.add_line((40, 0), (40, 20))
        msp.add_arc((20, 20), 20, 0, 180)  # the top: a half circle from (40, 20) to (0, 20)
        msp.add_line((0, 20), (0, 0))
        msp.add_line((60, 0), (80, 10))  # a stray line
        msp.add_text("tag")

    dxf_file(tmp_path, chain)
    loaded = load(tmp_path, scene({"file": "part.dxf", "units": "mm"}))
    assert loaded.slider.area * 1e6 == pytest.approx(40 * 20 + math.pi * 20 ** 2 / 2, rel=0.005)
    assert loaded.notes == ("slider.file: not read: 1 TEXT",
                            "slider.file: 1 open chain(s) of lines or arcs do not close and are not read")


# --- bad input --------------------------------------------------------------------------------------

def self_crossing(folder: Path) -> None:
    svg_file(folder, '<path d="M 0 0 L 50 50 L 50 0 L 0 50 Z"/>')


def no_footprint(folder: Path) -> None:
    trimesh.creation.icosphere(radius=20).export(folder / "part.stl")


def noise(size: int, suffix: str):
    def make(folder: Path) -> None:
        with open(folder / f"part{suffix}", "wb") as f:
            f.write(np.random.default_rng(1).bytes(min(size, MAX_FILE_BYTES + 1_000_000)))
            f.truncate(size)  # beyond the cap, the rest need not be written to be refused
    return make


def block_bomb(folder: Path) -> None:
    """A few hundred bytes of blocks: ten texts, then seven levels of ten references each to the
    level below, 10 ** 8 texts when expanded."""
    doc = ezdxf.new()
    for k in range(10):
        (doc.blocks.get("B0") or doc.blocks.new("B0")).add_text("x")
    for level in range(1, 8):
        block = doc.blocks.new(f"B{level}")
        for k in range(10):
            block.add_blockref(f"B{level - 1}", (k, 0))
    doc.modelspace().add_blockref("B7", (0, 0))
    doc.saveas(folder / "part.dxf")


def part_on_layer(layer: str):
    return lambda folder: dxf_file(folder, lambda msp: rounded_rectangle(msp, layer))


def use_fan(folder: Path) -> None:
    """Issue 41: 1.5 KB of groups of five <use> of the group below, ten levels: 5 ** 10 squares
    once svgelements expands them (it hung)."""
    levels = "".join(f'<g id="l{k}">' + "".join(f'<use href="#l{k - 1}" x="{x}"/>' for x in range(5)) + "</g>"
                     for k in range(1, 11))
    svg_file(folder, f'<defs><g id="l0"><rect width="1" height="1"/></g>{levels}</defs><use href="#l10"/>')


def use_chain(depth: int):
    """<use> nested ``depth`` deep: each level a group holding one use of the level below."""
    levels = "".join(f'<g id="l{k}"><use xlink:href="#l{k - 1}"/></g>' for k in range(1, depth + 1))
    return lambda folder: (folder / "part.svg").write_text(
        '<svg xmlns="http://www.w3.org/2000/svg" xmlns:xlink="http://www.w3.org/1999/xlink" viewBox="0 0 9 9">'
        f'<defs><rect id="l0" width="1" height="1"/>{levels}</defs><use xlink:href="#l{depth}"/></svg>')


def splines(count: int, fit_points: int):
    """``count`` splines through ``fit_points`` points round a circle of radius 50 mm."""
    def draw(msp) -> None:
        angles = np.linspace(0, 2 * np.pi, fit_points)
        for k in range(count):
            msp.add_spline(np.c_[50 * np.cos(angles) + 200 * k, 50 * np.sin(angles)])
    return lambda folder: dxf_file(folder, draw)


def overlapping_arcs(copies: int, spans: int):
    """``copies`` of ``spans`` arcs of one circle of radius 20 mm, each of a random span: issue 41's
    fuzzing found their union (how open pieces were joined) took 24 s for 300 and 6.5 s for 500
    copies of one (2,000 took all the memory)."""
    def draw(msp) -> None:
        rng = np.random.default_rng(1)
        for _ in range(spans):
            start = rng.uniform(0, 360)
            for _ in range(copies):
                msp.add_arc((0, 0), 20, start, start + rng.uniform(30, 170))
    return lambda folder: dxf_file(folder, draw)


def ply_of_a_missing_vertex(folder: Path) -> None:
    """A box as ASCII PLY whose last face refers to vertex 99 of its 8."""
    text = trimesh.creation.box((10, 10, 10)).export(file_type="ply", encoding="ascii").decode().rstrip("\n")
    (folder / "part.ply").write_text(text.rpartition(" ")[0] + " 99\n")


def binary_dxf(folder: Path) -> None:
    doc = ezdxf.new()
    rounded_rectangle(doc.modelspace())
    doc.saveas(folder / "part.dxf", fmt="bin")


def huge_bulge(folder: Path) -> None:
    dxf_file(folder, lambda msp: msp.add_lwpolyline([(0, 0, 1e300), (10, 0, 0), (10, 10, 0)], format="xyb",
                                                     close=True))


def box_stl(size_in_file: tuple[float, float, float]):
    """An STL box of ``size_in_file`` (the file's numbers), resting on z = 0."""
    return lambda folder: trimesh.creation.box(size_in_file).apply_translation(
        (0, 0, size_in_file[2] / 2)).export(folder / "part.stl")


def svg_text(text: str):
    return lambda folder: (folder / "part.svg").write_text(
        f'<svg xmlns="http://www.w3.org/2000/svg" {text}</svg>')


BAD = {
    # (what to write, the slider's file reference, the field named, words of the problem)
    "an SVG path that is a lone Z": (svg_text('width="100mm" height="100mm" viewBox="0 0 100 100"><path d="Z"/>'),
                                     {"file": "part.svg", "units": "mm"}, "slider.file", ["holds no closed outline"]),
    "an SVG viewBox of zero": (svg_text('width="100mm" height="100mm" viewBox="0 0 0 0"><rect width="9" height="9"/>'),
                               {"file": "part.svg", "units": "mm"}, "slider.file", ["viewBox, width or height is zero"]),
    "an SVG page of zero size": (svg_text('width="0" height="0" viewBox="0 0 100 100"><rect width="9" height="9"/>'),
                                 {"file": "part.svg", "units": "mm"}, "slider.file", ["viewBox, width or height is zero"]),
    "missing file": (lambda folder: None, {"file": "none.dxf", "units": "mm"}, "slider.file", ["cannot read"]),
    "unreadable file (a folder)": (lambda folder: (folder / "dir.svg").mkdir(), {"file": "dir.svg", "units": "mm"},
                                   "slider.file", ["not a regular file (a folder)"]),
    "unknown unit": (part_on_layer("PART"), {"file": "part.dxf", "units": "ft"}, "slider.units",
                     ["must be one of mm, cm, m, in", "'ft'"]),
    "a unit that is a list": (part_on_layer("PART"), {"file": "part.dxf", "units": ["mm"]}, "slider.units",
                              ["must be one of mm, cm, m, in", "['mm']"]),
    "no closed outline on the layer": (part_on_layer("PART"), {"file": "part.dxf", "units": "mm", "layer": "CUT"},
                                       "slider.file", ["holds no closed outline on layer 'CUT'"]),
    "an open polyline only": (lambda folder: dxf_file(folder, lambda msp: msp.add_lwpolyline([(0, 0), (9, 0), (9, 9)])),
                              {"file": "part.dxf", "units": "mm"}, "slider.file",
                              ["no closed outline; 1 open chain(s) of lines or arcs do not close"]),
    "self-intersecting SVG outline": (self_crossing, {"file": "part.svg", "units": "mm"}, "slider.file",
                                      ["outline 0 intersects itself"]),
    "mesh with no footprint": (no_footprint, {"file": "part.stl", "units": "mm"}, "slider.file",
                               ["no footprint", "only at points or along edges"]),
    "100 MB of noise": (noise(100_000_000, ".dxf"), {"file": "part.dxf", "units": "mm"}, "slider.file",
                        [f"larger than {MAX_FILE_BYTES} bytes"]),
    "noise as DXF": (noise(200_000, ".dxf"), {"file": "part.dxf", "units": "mm"}, "slider.file",
                     ["not a readable DXF file"]),
    "noise as SVG": (noise(200_000, ".svg"), {"file": "part.svg", "units": "mm"}, "slider.file",
                     ["not a readable SVG file"]),
    "noise as STL": (noise(200_000, ".stl"), {"file": "part.stl", "units": "mm"}, "slider.file", []),
    "blocks of references to blocks": (block_bomb, {"file": "part.dxf", "units": "mm"}, "slider.file",
                                       ["draws more than 10000 entities"]),
    "an unknown kind of file": (noise(10, ".step"), {"file": "part.step", "units": "mm"}, "slider.file",
                                ["unknown kind of file"]),
    "a chord below a micron": (part_on_layer("PART"), {"file": "part.dxf", "units": "mm", "chord": 1e-9},
                               "slider.chord", ["at least 1e-06 m"]),
    "a part beyond 1000 m": (part_on_layer("PART"), {"file": "part.dxf", "units": "m"}, "slider.file",
                             ["beyond the 1000 m limit"]),
    "two parts and no layer": (lambda folder: dxf_file(folder, two_parts), {"file": "part.dxf", "units": "mm"},
                               "slider.file", ["holds 2 parts"]),
    "an unknown key": (part_on_layer("PART"), {"file": "part.dxf", "units": "mm", "layers": "PART"},
                       "slider.layers", ["did you mean layer?"]),
    # Issue 41: each ran out of time or memory, or printed more than one line.
    "SVG <use> fanning out ten levels": (use_fan, {"file": "part.svg", "units": "mm"}, "slider.file",
                                         ["expands to more than 10000 elements (<use> copies counted)"]),
    "SVG <use> nested nine deep": (use_chain(9), {"file": "part.svg", "units": "mm"}, "slider.file",
                                   ["nests <use> more than 8 deep"]),
    "an SVG <use> of its own group": (svg_text('viewBox="0 0 9 9"><g id="a"><use href="#a"/></g>'),
                                      {"file": "part.svg", "units": "mm"}, "slider.file",
                                      ["a <use> refers to an element that holds it"]),
    "SVG groups nested 150 deep": (svg_text('viewBox="0 0 9 9">' + "<g>" * 150 + '<rect width="1" height="1"/>'
                                            + "</g>" * 150), {"file": "part.svg", "units": "mm"}, "slider.file",
                                   ["nests elements more than 100 deep"]),
    "an SVG path of 200,001 lines": (svg_text('viewBox="0 0 9 9"><path d="M 0 0' + " L 1 1" * 200_001 + '"/>'),
                                     {"file": "part.svg", "units": "mm"}, "slider.file",
                                     ["more than 200000 points of path data"]),
    "a circle used 729 times over itself": (lambda folder: svg_file(folder, '<defs><circle id="c0" cx="50" cy="50" r="9"/>'
                                                                  + "".join(f'<g id="c{k}">' + f'<use href="#c{k - 1}"/>' * 3
                                                                            + "</g>" for k in range(1, 7)) + '</defs><use href="#c6"/>'),
                                            {"file": "part.svg", "units": "mm"}, "slider.file",
                                            ["outlines 0 and 1 cross each other (or touch)"]),
    "2,000 squares one inside the next": (lambda folder: svg_file(folder, "".join(
        f'<rect x="{-k}" y="{-k}" width="{2 * k + 1}" height="{2 * k + 1}"/>' for k in range(2000))),
        {"file": "part.svg", "units": "mm"}, "slider.file", ["nest or overlap too much to check: more than 100000 pairs"]),
    "a spline through 20,000 points": (splines(1, 20_000), {"file": "part.dxf", "units": "mm"}, "slider.file",
                                       ["SPLINE #", "has 20000 fit points, more than 1000"]),
    "21 splines through 500 points": (splines(21, 500), {"file": "part.dxf", "units": "mm"}, "slider.file",
                                            ["its splines have more than 10000 fit points in all"]),
    "300 arcs overlapping on one circle": (overlapping_arcs(1, 300), {"file": "part.dxf", "units": "mm"},
                                           "slider.file", ["holds no closed outline;", "open chain(s)"]),
    "1,000 copies of one arc": (overlapping_arcs(1000, 1), {"file": "part.dxf", "units": "mm"}, "slider.file",
                                ["holds no closed outline; 1 open chain(s)"]),
    "a binary DXF": (binary_dxf, {"file": "part.dxf", "units": "mm"}, "slider.file",
                     ["a binary DXF file, which is not read: save it as ASCII DXF"]),
    "a bulge of 1e300": (huge_bulge, {"file": "part.dxf", "units": "mm"}, "slider.file",
                         ["LWPOLYLINE #", "cannot be drawn"]),
    "an STL in metres declared mm": (box_stl((0.08, 0.05, 0.02)), {"file": "part.stl", "units": "mm"}, "slider.units",
                                     ["um across, less than 1/100 of the pusher's width (30 mm)",
                                      "is the file in metres? (units: mm)"]),
    "an STL in mm declared metres": (box_stl((80, 50, 20)), {"file": "part.stl", "units": "m"}, "slider.units",
                                     ["94.34 m across, more than the workspace's diagonal (2.828 m)",
                                      "is the file in millimetres? (units: m)"]),
    "a PLY face of a vertex it lacks": (ply_of_a_missing_vertex, {"file": "part.ply", "units": "mm"}, "slider.file",
                                        ["a face refers to vertex 99, which the mesh does not have (it has 8)"]),
    "an OBJ vertex of one coordinate": (lambda folder: (folder / "part.obj").write_text(
        "v -20\nv 20 -20 0\nv 20 20 0\nf 1 2 3\n"), {"file": "part.obj", "units": "mm"}, "slider.file",
                                        ["its vertices have 1 coordinates, not x, y, z"]),
    "object and name both": (part_on_layer("PART"), {"file": "part.dxf", "units": "mm", "object": "A", "name": "A"},
                             "slider.name", ["is object's other name: give one of them"]),
}


@pytest.mark.parametrize("case", BAD, ids=str)
def test_bad_cad_input_exits_1_with_one_line_and_writes_nothing(case, tmp_path, monkeypatch, capsys):
    make, slider, field, words = BAD[case]
    if case == "a part beyond 1000 m":
        slider = {**slider, "at": [0, 0, 0]}
        make(tmp_path)
        (tmp_path / "part.dxf").write_bytes((tmp_path / "part.dxf").read_bytes().replace(b"\n40.0\n", b"\n4e6\n", 1))
    else:
        make(tmp_path)
    (tmp_path / "scene.yaml").write_text(yaml.safe_dump(scene(slider)))
    before = {p.name for p in tmp_path.iterdir()}
    monkeypatch.chdir(tmp_path)
    tracemalloc.start()
    clock = time.perf_counter()
    try:
        assert main(["scene.yaml", "--out", "out", "--export-scene", "exported.yaml"]) == 1
        seconds, peak = time.perf_counter() - clock, tracemalloc.get_traced_memory()[1]
    finally:
        tracemalloc.stop()
    captured = capsys.readouterr()
    assert captured.out == "" and error_field(captured.err) == field
    assert all(word in captured.err for word in words), captured.err
    assert len(captured.err) <= 301
    assert_nothing_written(tmp_path, before)
    assert seconds < 5.0 and peak < 100e6  # bounded by the caps, not by the file (tracemalloc slows it 2-5x)
    with pytest.raises(SceneError) as raised:  # the library says the same
        load_scene("scene.yaml")
    assert captured.err == f"plan: error: {raised.value}\n"


def test_without_the_cad_extra_a_file_is_one_line_naming_it(tmp_path, monkeypatch, capsys):
    dxf_file(tmp_path, rounded_rectangle)
    (tmp_path / "scene.yaml").write_text(yaml.safe_dump(scene({"file": "part.dxf", "units": "mm"})))
    monkeypatch.chdir(tmp_path)
    monkeypatch.setitem(sys.modules, "ezdxf", None)  # as if not installed: importing it fails
    assert main(["scene.yaml", "--out", "out"]) == 1
    err = capsys.readouterr().err
    assert error_field(err) == "slider.file" and "needs the cad extra: pip install 'stablepush[cad]'" in err
    assert_nothing_written(tmp_path, {"scene.yaml", "part.dxf"})


@pytest.mark.parametrize("argv, words", [(["--export-scene", "."], "is a folder"),
                                         (["--export-scene", "x.yaml", "--seeds", "1:2"], "not a batch")])
def test_bad_export_flag_exits_1(argv, words, tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main([str(ROOT / "scenes" / "battery.yaml"), *argv, "--out", "out"]) == 1
    err = capsys.readouterr().err
    assert error_field(err) == "--export-scene" and words in err
    assert_nothing_written(tmp_path, set())


def test_an_export_that_cannot_be_written_exits_4_naming_it(tmp_path, monkeypatch, capsys):
    monkeypatch.chdir(tmp_path)
    assert main([str(ROOT / "scenes" / "battery.yaml"), "--out", "out", "--export-scene", "no/scene.yaml"]) == 4
    assert capsys.readouterr().err.startswith("plan: error: cannot write 'no/scene.yaml': No such file or directory")
    assert not (tmp_path / "no").exists()


def test_the_export_holds_the_options_the_flags_set(tmp_path, monkeypatch):
    monkeypatch.chdir(tmp_path)
    argv = ["--out", "out", "--export-scene", "again.yaml", "--transit", "lift", "--switch-cost", "0.1", "--seed", "7"]
    assert main([str(ROOT / "scenes" / "battery.yaml"), *argv]) == 0
    again = load_scene(tmp_path / "again.yaml")
    assert again.options.transit == "lift" and again.options.switch_cost == 0.1 and again.options.seed == 7


#: Issue 41's files that ran out of time or memory, or printed warnings before the error line.
HEAVY = ["SVG <use> fanning out ten levels", "a spline through 20,000 points", "a bulge of 1e300",
         "an STL in metres declared mm"]
FOUR_GB = 4 * 2 ** 30


@pytest.mark.parametrize("case", HEAVY)
def test_issue_41_files_end_at_once_in_one_line_under_a_4_gb_address_space(case, tmp_path):
    """The command as a user runs it, in a process that cannot have more than 4 GB: one line on
    stderr (no RuntimeWarning above it), exit 1, within seconds. Before: a hang, 9.2 GB, two
    warning lines, 24 GB."""
    make, slider, field, words = BAD[case]
    make(tmp_path)
    (tmp_path / "scene.yaml").write_text(yaml.safe_dump(scene(slider)))
    before = {p.name for p in tmp_path.iterdir()}
    clock = time.monotonic()
    run = subprocess.run([str(PLAN), "scene.yaml", "--out", "out"], cwd=tmp_path, capture_output=True, text=True,
                         timeout=120, preexec_fn=lambda: resource.setrlimit(resource.RLIMIT_AS, (FOUR_GB, FOUR_GB)))
    assert time.monotonic() - clock < 20
    assert (run.returncode, run.stdout) == (1, "") and error_field(run.stderr) == field
    assert all(word in run.stderr for word in words), run.stderr
    assert_nothing_written(tmp_path, before)


def circle(radius: float):
    return lambda folder: dxf_file(folder, lambda msp: msp.add_circle((0, 0), radius), "circle.dxf")


def test_an_outline_past_the_vertex_cap_is_read_at_a_coarser_chord_with_a_note(tmp_path):
    """Issue 41: a circle of radius 999,999 mm at the least chord flattened to 131,073 vertices
    (the part's edges, each checked against every other: over 120 s). It keeps at most
    MAX_VERTICES, every one within the chord the note gives of the circle; that chord is within
    eight times the least any polygon of that many vertices can have (its sagitta): simplifying
    a regular polygon halves its vertices (1000 are 512: four times the sagitta), and the
    tolerance doubles until they fit (twice that at most)."""
    circle(999_999)(tmp_path)
    part = {"vertices": [[0, 0], [0.08, 0], [0.08, 0.05], [0, 0.05]]}
    loaded = load(tmp_path, scene(part, [{"file": "circle.dxf", "units": "mm", "chord": 1e-6}],
                                  workspace={"min": [-1000, -1000], "max": [1000, 1000]},
                                  start=[990, 990, 0], goal=[980, 990, 0]))
    (note,) = loaded.notes
    found = re.fullmatch(r"obstacles\[0\]\.file: an outline keeps (\d+) vertices at chord 1e-06 m, more than 1000: "
                         r"read at chord (\S+) m", note)
    assert found and int(found.group(1)) > MAX_VERTICES, note
    chord = float(found.group(2))
    outline = np.asarray(loaded.obstacles[0].exterior.coords)[:-1]
    assert len(outline) <= MAX_VERTICES
    assert np.abs(np.hypot(*outline.T) - 999.999).max() <= chord
    assert chord <= 8 * 999.999 * (1 - math.cos(math.pi / MAX_VERTICES))


def test_the_command_plans_past_an_outline_read_at_a_coarser_chord_and_says_so(tmp_path, monkeypatch, capsys):
    circle(500)(tmp_path)  # 4096 vertices at the least chord
    part = {"vertices": [[-0.04, -0.025], [0.04, -0.025], [0.04, 0.025], [-0.04, 0.025]]}
    obstacle = {"file": "circle.dxf", "units": "mm", "chord": 1e-6, "at": [0, 0.6, 0]}
    (tmp_path / "scene.yaml").write_text(yaml.safe_dump(scene(part, [obstacle], goal=[0.5, -0.5, 0])))
    monkeypatch.chdir(tmp_path)
    assert main(["scene.yaml", "--out", "out"]) == 0
    err = capsys.readouterr().err
    assert re.fullmatch(r"plan: note: obstacles\[0\]\.file: an outline keeps \d+ vertices at chord 1e-06 m, more "
                        r"than 1000: read at chord \S+ m\n", err), err


def test_splines_control_points_are_capped_in_all_before_they_are_drawn(tmp_path, monkeypatch):
    """The cap is MAX_POINTS (a spline of 200,001 control points is an 8 MB file): a tenth of it
    here, so that a few points make the file."""
    def draw(msp) -> None:
        for k in range(2):
            msp.add_open_spline([(x, 20 * k + (x % 2)) for x in range(12)])

    dxf_file(tmp_path, draw)
    monkeypatch.setattr("planner.model.cad.dxf.MAX_POINTS", 20)  # the first spline's 12 pass, not 24 in all
    monkeypatch.setattr("planner.model.cad.dxf.flattened", lambda path, *args: np.zeros((0, 2)))  # no point counted
    with pytest.raises(SceneError, match="slider.file: its splines have more than 20 control points in all"):
        load(tmp_path, scene({"file": "part.dxf", "units": "mm"}))


def two_boxes_obj(folder: Path) -> None:
    """An OBJ of two objects: 'left', a 10 mm cube at the origin, and 'right', a 5 mm one at x = 30 mm."""
    lines, offset = [], 1
    for name, size, x in (("left", 10, 0), ("right", 5, 30)):
        box = trimesh.creation.box((size, size, size)).apply_translation((x, 0, size / 2))
        lines += [f"o {name}", *(f"v {a} {b} {c}" for a, b, c in box.vertices),
                  *(f"f {i + offset} {j + offset} {k + offset}" for i, j, k in box.faces)]
        offset += len(box.vertices)
    (folder / "parts.obj").write_text("\n".join(lines) + "\n")


def test_an_obj_object_is_picked_by_its_name(tmp_path):
    two_boxes_obj(tmp_path)
    right = load(tmp_path, scene({"file": "parts.obj", "units": "mm", "object": "right"})).slider
    assert right.polygon.bounds == pytest.approx((0.0275, -0.0025, 0.0325, 0.0025), abs=1e-9)
    left = load(tmp_path, scene({"file": "parts.obj", "units": "mm", "name": "left"})).slider  # name: the same
    assert left.polygon.bounds == pytest.approx((-0.005, -0.005, 0.005, 0.005), abs=1e-9)
    with pytest.raises(SceneError, match=r"slider.file: no body named 'middle' \(bodies: 'left', 'right'\)"):
        load(tmp_path, scene({"file": "parts.obj", "units": "mm", "object": "middle"}))
    with pytest.raises(SceneError, match="slider.file: holds 2 parts: pick one with layer or object"):
        load(tmp_path, scene({"file": "parts.obj", "units": "mm"}))


def test_a_trays_parts_name_themselves_and_object_picks_from_the_file(tmp_path, monkeypatch, capsys):
    """Issue 41: a part's ``name`` (its name in the tray) hid the file's ``name`` selector. In
    ``parts:`` it names the part alone; ``object`` picks from the file, here the other way round."""
    two_boxes_obj(tmp_path)
    parts = [{"name": "left", "file": "parts.obj", "units": "mm", "object": "right", "start": [-0.3, 0, 0],
              "goal": [0.3, 0, 0]},
             {"name": "right", "file": "parts.obj", "units": "mm", "object": "left", "start": [0, 0.3, 0],
              "goal": [0, 0.3, 0]}]
    data = {"parts": parts, "pusher": PUSHER, "workspace": {"min": [-1, -1], "max": [1, 1]}}
    tray = load(tmp_path, data)
    assert tray.names == ("left", "right")
    assert [p.slider.area for p in tray.parts] == pytest.approx([25e-6, 100e-6])
    (tmp_path / "scene.yaml").write_text(yaml.safe_dump(data))
    monkeypatch.chdir(tmp_path)
    assert main(["scene.yaml", "--out", "out"]) == 0
    assert capsys.readouterr().out.startswith("solved: 2 parts")
    del parts[0]["object"]  # the part's name picks nothing
    with pytest.raises(SceneError, match=r"parts\[0\].file: holds 2 parts: pick one with layer or object"):
        load(tmp_path, data)


def test_a_part_of_vertices_far_too_small_for_its_pusher_names_them_in_metres(tmp_path):
    tiny = {"vertices": [[0, 0], [80e-6, 0], [80e-6, 50e-6], [0, 50e-6]]}
    with pytest.raises(SceneError, match=r"^slider.vertices: the part is 94.34 um across, less than 1/100 of the "
                                         r"pusher's width \(30 mm\): the vertices are in metres$"):
        load(tmp_path, scene(tiny))


def test_an_outline_of_arcs_drawn_many_times_over_is_read_once(tmp_path):
    """Two half circles, each drawn 1,000 times, and a stray line from one of their joints: one
    outline (a piece drawn twice counts once; a piece leading nowhere is cut off), read at once."""
    def draw(msp) -> None:
        for _ in range(1000):
            msp.add_arc((0, 0), 20, 0, 180)
            msp.add_arc((0, 0), 20, 180, 360)
        msp.add_line((20, 0), (40, 0))

    dxf_file(tmp_path, draw)
    clock = time.perf_counter()
    loaded = load(tmp_path, scene({"file": "part.dxf", "units": "mm"}))
    assert time.perf_counter() - clock < 5.0
    assert math.pi * (20 - 0.1) ** 2 < loaded.slider.area * 1e6 < math.pi * 20 ** 2
    assert loaded.notes == ("slider.file: 1 open chain(s) of lines or arcs do not close and are not read",)


def test_what_ezdxf_repairs_is_a_note_not_its_log_lines(tmp_path):
    """A coordinate that is not a number ("0.0abc") is read by ezdxf as 0.0, which it logged: two
    lines Python's last-resort handler printed above the outcome. Now one note says so."""
    dxf_file(tmp_path, lambda msp: msp.add_lwpolyline([(0, 0), (40, 0), (40, 30), (0, 30)], close=True))
    text = (tmp_path / "part.dxf").read_text()
    first = text.index("\n 10\n", text.index("AcDbPolyline")) + 5
    (tmp_path / "part.dxf").write_text(text[:first] + "0.0abc" + text[text.index("\n", first):])
    data = scene({"file": "part.dxf", "units": "mm"}, start=[0, 0, 0], goal=[0, 0, 0])
    note = ("slider.file: ezdxf repaired 2 errors of the file (the first: 'recovered invalid floating point value "
            '"0.0abc" near line')
    assert load(tmp_path, data).notes[0].startswith(note)
    run = subprocess.run([str(PLAN), "scene.yaml", "--out", "out"], cwd=tmp_path, capture_output=True, text=True,
                         timeout=120)
    assert run.returncode == 0 and run.stdout.startswith("solved: 0 pushes")
    assert run.stderr.startswith(f"plan: note: {note}") and run.stderr.count("\n") == 1, run.stderr


# --- the example, planned and verified against its exported scene ------------------------------------

def plans_and_verifies_against_its_export(path: Path, tmp_path: Path) -> dict:
    """Plan ``path`` (seed 1) with --export-scene, then verify the plan against the exported file;
    return the exported scene."""
    exported = tmp_path / "exported.yaml"
    assert main([str(path), "--seed", "1", "--out", str(tmp_path / "out"), "--export-scene", str(exported)]) == 0
    scene = load_scene(path)
    plan = tmp_path / "out" / f"{scene.name}.json"
    assert main([str(exported), "--plan", str(plan), "--verify", "10", "--out", str(tmp_path / "check")]) == 0
    again = load_scene(exported)
    assert again.slider.vertices.tolist() == scene.slider.vertices.tolist()
    assert again.slider.cf.tolist() == scene.slider.cf.tolist()
    assert [o.exterior.coords[:] for o in again.obstacles] == [o.exterior.coords[:] for o in scene.obstacles]
    assert again.start.tolist() == scene.start.tolist() and again.goal.tolist() == scene.goal.tolist()
    return yaml.safe_load(exported.read_text())


def test_the_example_scene_plans_and_verifies_against_its_exported_scene(tmp_path, capsys):
    data = plans_and_verifies_against_its_export(ROOT / "scenes" / "cad" / "bracket.yaml", tmp_path)
    assert set(data["slider"]) == {"vertices", "cf", "cf_uncertainty"}
    assert all(set(o) == {"polygon", "height"} for o in data["obstacles"])  # the CAD files resolved to outlines
    assert "plan: note: obstacles[0].file: not read: 1 text" in capsys.readouterr().err
    # The scene pushes edges 0, 7, 13 and 14: the plate's straight sides, the rest being its arcs.
    vertices = np.array(data["slider"]["vertices"])
    lengths = np.hypot(*(np.roll(vertices, -1, axis=0) - vertices).T)
    assert data["pusher"]["edges"] == [0, 7, 13, 14] and sorted(np.flatnonzero(lengths > 0.02)) == [0, 7, 13, 14]
    # The CF is the plate's centroid moved away from the 12 mm bolt hole at (15, 5) mm.
    outline = load_scene(ROOT / "scenes" / "cad" / "bracket.yaml").slider.polygon
    hole = math.pi * 0.006 ** 2
    cf = (outline.area * np.array(outline.centroid.coords[0]) - hole * np.array([0.015, 0.005])) / (outline.area - hole)
    assert np.abs(np.array(data["slider"]["cf"]) - cf).max() < 5e-5


def test_a_scene_with_an_stl_part_and_an_svg_fixture_plans_and_verifies(tmp_path):
    foot = trimesh.creation.box((30, 30, 10)).apply_translation((0, 0, 5))
    top = trimesh.creation.box((50, 30, 5)).apply_translation((5, 0, 12.5))
    trimesh.util.concatenate([foot, top]).export(tmp_path / "part.stl")
    svg_file(tmp_path, '<path d="M 0 0 L 40 0 Q 60 30 40 60 L 0 60 L 0 50 L 30 50 Q 40 30 30 10 L 0 10 Z"/>',
             "fixture.svg")
    data = {"name": "mushroom", "slider": {"file": "part.stl", "units": "mm"},
            "pusher": {"width": 0.02, "depth": 0.01, "mu": 0.6},
            "obstacles": [{"file": "fixture.svg", "units": "cm", "at": [0.1, 0.3, 0]}],
            "workspace": {"min": [-0.3, -0.3], "max": [0.6, 0.4]}, "start": [-0.2, 0.0, 0], "goal": [0.3, 0.0, 0],
            "tolerance": {"position": 0.02, "angle": 5}}
    (tmp_path / "scene.yaml").write_text(yaml.safe_dump(data))
    exported = plans_and_verifies_against_its_export(tmp_path / "scene.yaml", tmp_path)
    assert exported["slider"]["cf"] == pytest.approx([0, 0], abs=1e-7)  # the foot's centre, not the top's


def test_a_plain_scene_round_trips_through_its_export(tmp_path):
    scene = load_scene(ROOT / "scenes" / "nonconvex.yaml")
    from planner.model.scene_file import write_scene

    write_scene(scene, tmp_path / "again.yaml")
    again = load_scene(tmp_path / "again.yaml")
    for name in ("start", "goal"):
        assert getattr(again, name).tolist() == getattr(scene, name).tolist()
    assert again.obstacles == scene.obstacles and again.pusher == scene.pusher and again.options == scene.options
    assert parse_scene(yaml.safe_load((tmp_path / "again.yaml").read_text())).slider.cf.tolist() == \
        scene.slider.cf.tolist()
