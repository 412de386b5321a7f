"""Parts and obstacles read from CAD files: DXF drawings (:mod:`.dxf`), SVG drawings (:mod:`.svg`)
and meshes (:mod:`.mesh`: STL, OBJ, PLY).

Wherever a scene takes a polygon it may name a file instead, ``{file, units, at, layer, object,
chord}`` (:data:`FILE_KEYS`, :data:`FILE_OPTIONS`; the README's "Parts and obstacles from CAD
files"). :func:`read_shapes` reads it into :class:`Shape`\\ s in metres, placed by ``at``: each
is what the body covers seen from above (``region``, holes open) and what of it rests on the
table (``footprint``). Curves are flattened to within half the chord tolerance of the curve and
the result simplified within the other half, so that no point of an outline is farther than the
chord tolerance from the drawing. An outline that would keep more than :data:`MAX_VERTICES`
vertices is simplified further, with a note saying to what tolerance.

The readers' libraries (ezdxf, svgelements, trimesh: the ``cad`` extra) are imported only when a
scene names a file of their kind; without them the scene is refused with one line naming the extra,
and their log records are not printed. A file is untrusted input: at most :data:`MAX_FILE_BYTES`
are read, a drawing draws at most :data:`MAX_ENTITIES` entities or elements (references expanded),
coordinates are checked against the scene's limits before any curve is flattened, and flattening
stops at :data:`MAX_POINTS` points, so time and memory are bounded by those numbers, not by the
file's. Floating-point overflow inside the readers' libraries is not reported (a warning line would
precede the error): what they return is checked to be finite instead. What the readers rely on in
their libraries is in docs/stack.md, "CAD readers".
"""

from __future__ import annotations

import importlib
import itertools
import logging
import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np
import shapely
import shapely.affinity
import shapely.ops
from shapely.validation import explain_validity

from ..fields import ANGLE, LENGTH, SceneError, number, shown, vector
from ..input_file import read_bytes

if TYPE_CHECKING:
    import ezdxf.path

__all__ = ["CHORD", "FILE_KEYS", "FILE_OPTIONS", "MAX_ENTITIES", "MAX_FILE_BYTES", "MAX_OVERLAPS", "MAX_POINTS",
           "MAX_VERTICES", "READERS", "UNITS", "Selection", "Shape", "flattened", "read_shapes", "shapes_from_rings", "without_holes"]

#: Required keys of a file reference, and its optional ones. ``name`` is ``object``'s other name,
#: where it names nothing else (a part of ``parts:`` has a name of its own).
FILE_KEYS = ("file", "units")
FILE_OPTIONS = ("at", "layer", "object", "name", "chord")
#: Metres per unit of the file's numbers.
UNITS = {"mm": 1e-3, "cm": 1e-2, "m": 1.0, "in": 0.0254}
#: Default chord tolerance, in metres (0.1 mm), and the least one taken (a micron: the least edge
#: of a part, :data:`..scene.MIN_SIZE`).
CHORD = 1e-4
MIN_CHORD = 1e-6
#: Largest file read: a drawing of a part or fixture is kilobytes; ten megabytes is a detailed
#: mesh of some 200000 triangles, and the readers' memory stays within a few hundred megabytes.
MAX_FILE_BYTES = 10_000_000
#: Most points the curves of one file may flatten to (or triangles a mesh may hold).
MAX_POINTS = 200_000
#: Most entities (DXF) or elements (SVG) a drawing may draw, its block references or ``<use>``
#: elements expanded: a drawing of parts holds thousands; a few hundred bytes of references to
#: references would otherwise expand to billions.
MAX_ENTITIES = 10_000
#: Most vertices an outline keeps: each is an edge of the part, checked against every other for
#: whether a pusher can touch it (quadratic) and given a stable region if it can (0.1-0.25 s each).
#: A circle of 10 m radius at the default chord has a thousand; a 1 km one at the least chord
#: would have 131,073.
MAX_VERTICES = 1_000
#: Most pairs of a file's outlines whose extents overlap: each pair is compared (do they cross,
#: does one hold the other), a few microseconds each. The holes of a plate or a sheet of parts
#: overlap little (10,000 holes are 20,000 pairs); 10,000 outlines one inside the next are 50
#: million (107 s and 2.8 GB), and a <use> of a shape copied 729 times 266,000 (12 s).
MAX_OVERLAPS = 100_000
#: The reader module for each file suffix.
READERS = {".dxf": "dxf", ".svg": "svg", ".stl": "mesh", ".obj": "mesh", ".ply": "mesh"}


@dataclass(frozen=True)
class Shape:
    """One body of a file: ``region``, what it covers seen from above (its outline with through
    holes open), and ``footprint``, what of it rests on the table. A drawing's two are the same;
    a mesh's footprint is its lowest faces."""

    region: shapely.Polygon
    footprint: shapely.Polygon | shapely.MultiPolygon


@dataclass(frozen=True)
class Selection:
    """What a reader is asked for: the ``layer`` and ``name`` given (None if not), the flattening
    tolerance ``chord`` and the largest coordinate magnitude ``limit``, both in the file's units,
    and ``field``, the file's field for messages."""

    layer: str | None
    name: str | None
    chord: float
    limit: float
    field: str

    def check_points(self, points: np.ndarray, what: str) -> None:
        """Refuse ``points`` (file units) that are not finite or lie beyond ``limit``."""
        if points.size and not np.all(np.abs(points) <= self.limit):  # NaN fails too
            bad = points[~np.all(np.abs(points) <= self.limit, axis=-1)][0]
            raise SceneError(self.field, f"{what} has a point beyond the {LENGTH.bound:g} m limit: {shown(bad)}")


def read_shapes(spec: dict[str, Any], field: str, folder: Path, notes: list[str]) -> list[Shape]:
    """The shapes of the file that ``spec`` (a mapping with :data:`FILE_KEYS` and perhaps
    :data:`FILE_OPTIONS`, already checked for unknown keys) names, relative to ``folder``, in
    metres and placed by its ``at``. Notes about what the file held and was not read (text, open
    chains) are appended to ``notes``.

    Raises
    ------
    SceneError
        Naming ``field`` (or its key at fault): the file cannot be read, is too large, is not of
        its kind, holds no closed outline, or an outline crosses itself or another; or a key's
        value is bad; or the reader's library (the ``cad`` extra) is not installed.
    """
    file = spec["file"]
    if not isinstance(file, str) or not file or not file.isprintable():
        raise SceneError(f"{field}.file", f"must be a file name, got {shown(file)}")
    units = spec["units"]
    if not isinstance(units, str) or units not in UNITS:
        raise SceneError(f"{field}.units", f"must be one of {', '.join(UNITS)}, got {shown(units)}")
    scale = UNITS[units]
    x, y, theta = vector(spec.get("at", [0.0, 0.0, 0.0]), f"{field}.at", 3)
    LENGTH.check(x, f"{field}.at[0]")
    LENGTH.check(y, f"{field}.at[1]")
    theta = math.radians(ANGLE.check(theta, f"{field}.at[2]"))
    chord = number(spec.get("chord", CHORD), f"{field}.chord", positive=True, limit=LENGTH)
    if chord < MIN_CHORD:
        raise SceneError(f"{field}.chord", f"must be at least {MIN_CHORD:g} m, got {shown(chord)}")
    if "object" in spec and "name" in spec:
        raise SceneError(f"{field}.name", "is object's other name: give one of them")
    select = {key: spec.get(key) for key in ("layer", "object", "name")}
    for key, value in select.items():
        if value is not None and (not isinstance(value, str) or not value):
            raise SceneError(f"{field}.{key}", f"must be a non-empty string, got {shown(value)}")
    path = folder / file
    kind = READERS.get(path.suffix.lower())
    if kind is None:
        raise SceneError(f"{field}.file", f"{shown(file)}: unknown kind of file (known: {', '.join(READERS)})")
    raw = read_bytes(path, f"{field}.file", MAX_FILE_BYTES)
    reader = importlib.import_module(f".{kind}", __name__)
    try:
        for library in reader.NEEDS:
            importlib.import_module(library)
    except ImportError as err:
        raise SceneError(f"{field}.file", f"reading {path.suffix.lower()} files needs the cad extra: "
                                          f"pip install 'stablepush[cad]' ({err})") from None
    for library in reader.NEEDS:
        # Their log records (a value ezdxf repaired, say) would reach stderr through Python's
        # last-resort handler, lines before the error or the outcome: the readers note what matters.
        logger = logging.getLogger(library)
        if not logger.handlers:
            logger.addHandler(logging.NullHandler())
    selection = Selection(select["layer"], select["object"] or select["name"], chord / 2 / scale, LENGTH.bound / scale,
                          f"{field}.file")
    noted = len(notes)
    with np.errstate(all="ignore"):  # overflow in the libraries (a bulge of 1e300): their output is checked
        shapes = reader.read(raw, path.suffix.lower(), selection, notes)
    if not shapes:  # what was not read may say why (open chains, text)
        why = "".join(f"; {note.removeprefix(selection.field + ': ')}" for note in notes[noted:])
        raise SceneError(f"{field}.file", f"{shown(file)} holds no closed outline{_where(selection)}{why}")
    c, s = math.cos(theta), math.sin(theta)
    matrix = [scale * c, -scale * s, scale * s, scale * c, x, y]
    placed = []
    for shape in shapes:
        region, footprint = (shapely.affinity.affine_transform(g, matrix) for g in (shape.region, shape.footprint))
        LENGTH.check(float(np.max(np.abs(region.bounds))), f"{field}.at")  # `at` moved it beyond the limit
        placed.append(_simplified(Shape(region, footprint), chord, f"{field}.file", notes))
    return placed


def _simplified(shape: Shape, chord: float, field: str, notes: list[str]) -> Shape:
    """``shape`` (metres) simplified within the other half of the chord tolerance ``chord``; the
    topology kept, so a valid region stays valid. If an outline keeps more than
    :data:`MAX_VERTICES` vertices, that result is simplified again within twice the tolerance,
    and twice that, until none does (every point is then within ``chord`` and the last
    tolerance of the drawing), and a note says to what chord.

    >>> disk = shapely.Point(0, 0).buffer(1.0, quad_segs=2000)  # 8000 vertices, within 8e-8 of a circle
    >>> notes = []
    >>> outline = _simplified(Shape(disk, disk), 1e-6, "f", notes).region.exterior
    >>> notes
    ['f: an outline keeps 4096 vertices at chord 1e-06 m, more than 1000: read at chord 3.3e-05 m']
    >>> len(outline.coords) - 1 <= MAX_VERTICES, bool(shapely.hausdorff_distance(outline, disk.exterior) <= 3.3e-05)
    (True, True)
    """
    simple = shape.region.simplify(chord / 2)
    region, tolerance = simple, chord / 2
    # Far past the shape's size every ring is at its fewest vertices: the doubling ends there.
    size = max(np.ptp(np.reshape(simple.bounds, (2, 2)), axis=0))
    while _most_vertices(region) > MAX_VERTICES and tolerance < size:
        tolerance *= 2
        # Tried first without keeping the topology, ten times faster; kept, it may keep more vertices.
        if _most_vertices(simple.simplify(tolerance, preserve_topology=False)) <= MAX_VERTICES:
            region = simple.simplify(tolerance)
    if _most_vertices(region) > MAX_VERTICES:
        raise SceneError(field, f"an outline keeps more than {MAX_VERTICES} vertices however coarse the chord")
    if region is simple:
        return Shape(simple, shape.footprint.simplify(chord / 2))
    notes.append(f"{field}: an outline keeps {_most_vertices(simple)} vertices at chord {chord:g} m, more than "
                 f"{MAX_VERTICES}: read at chord {chord + tolerance:.2g} m")
    return Shape(region, shape.footprint.simplify(chord / 2 + tolerance))


def _most_vertices(region: shapely.Polygon) -> int:
    """The most vertices of one ring of ``region`` (its outline or a hole)."""
    return max(len(ring.coords) - 1 for ring in (region.exterior, *region.interiors))


def flattened(path: ezdxf.path.Path, selection: Selection, what: str, room: int) -> np.ndarray:
    """The points of ``path`` (file units) flattened to ``selection``'s chord, as an ``(n, 2)``
    array; its control points are checked first (the curve lies in their hull: :meth:`Selection.check_points`).
    ``what`` names the path for messages; more than ``room`` points are refused, without making
    more than that."""
    selection.check_points(np.array([(v.x, v.y) for v in path.control_vertices()]).reshape(-1, 2), what)
    flat = np.array([(v.x, v.y) for v in itertools.islice(path.flattening(selection.chord), room + 1)]).reshape(-1, 2)
    if len(flat) > room:
        raise SceneError(selection.field, f"its curves flatten to more than {MAX_POINTS} points at this chord "
                                          "tolerance")
    return flat


def _where(selection: Selection) -> str:
    return "".join(f" {key} {shown(value)}" for key, value in (("on layer", selection.layer),
                                                               ("named", selection.name)) if value is not None)


def shapes_from_rings(rings: list[np.ndarray], selection: Selection) -> list[Shape]:
    """The bodies that closed ``rings`` (each ``(n, 2)``, file units, not repeating the first
    point) draw: each outline not inside another is a body; one inside exactly one other is a hole
    of it; one inside a hole is a body again (even-odd nesting, as a laser cutter reads a drawing).
    Outlines may nest but not cross, and none may cross itself; at most :data:`MAX_OVERLAPS`
    pairs of them may overlap in extent (each such pair is compared).

    >>> square = np.array([[0, 0], [4, 0], [4, 4], [0, 4]], float)
    >>> shapes = shapes_from_rings([square, square / 4 + 1, square / 8 + 1.25], Selection(None, None, 0.1, 1e3, "f"))
    >>> [(s.footprint.area, len(s.footprint.interiors)) for s in shapes]
    [(15.0, 1), (0.25, 0)]
    >>> shapes_from_rings([square, square + 2], Selection(None, None, 0.1, 1e3, "f"))
    Traceback (most recent call last):
    ...
    planner.model.fields.SceneError: f: outlines 0 and 1 cross each other (or touch)
    """
    polygons = []
    for k, ring in enumerate(rings):
        if len(ring) < 3 or shapely.MultiPoint(ring).convex_hull.area <= (selection.chord * 1e-3) ** 2:
            continue  # a point or a line drawn as a closed curve: no outline
        if not shapely.LinearRing(ring).is_simple:
            raise SceneError(selection.field, f"outline {k} intersects itself "
                                              f"({explain_validity(shapely.Polygon(ring)).lower()})")
        polygons.append(shapely.Polygon(ring))
    if not polygons:
        return []
    exteriors = shapely.get_exterior_ring(polygons)
    tree, overlaps = shapely.STRtree(exteriors), 0
    for k, exterior in enumerate(exteriors):  # the first crossing ends it: a thousand copies of one outline cost one pass
        near = tree.query(exterior)  # whose boxes overlap its own: nothing compared yet
        overlaps += len(near)
        if overlaps > MAX_OVERLAPS:
            raise SceneError(selection.field, f"its outlines nest or overlap too much to check: more than "
                                              f"{MAX_OVERLAPS} pairs of them overlap in extent")
        crossing = near[(near > k) & shapely.intersects(exterior, exteriors[near])]
        if crossing.size:
            raise SceneError(selection.field, f"outlines {k} and {crossing.min()} cross each other (or touch)")
    inside: list[list[int]] = [[] for _ in polygons]  # the outlines each is inside
    for outer, inner in shapely.STRtree(polygons).query(polygons, predicate="contains_properly").T:
        inside[inner].append(outer)
    bodies = {k: [] for k in range(len(polygons)) if len(inside[k]) % 2 == 0}
    for k, outer in enumerate(inside):
        if len(outer) % 2:  # a hole: of the body that holds it most tightly
            bodies[max(outer, key=lambda j: len(inside[j]))].append(polygons[k].exterior)
    shapes = []
    for k, holes in bodies.items():
        region = shapely.Polygon(polygons[k].exterior, holes)
        shapes.append(Shape(region, region))
    return shapes


def without_holes(region: shapely.Polygon) -> list[shapely.Polygon]:
    """``region`` cut into polygons without holes by a line across each hole (the scene's
    obstacles are plain polygons).

    >>> frame = shapely.box(0, 0, 4, 4).difference(shapely.box(1, 1, 3, 3))
    >>> sorted(p.area for p in without_holes(frame))
    [6.0, 6.0]
    """
    if not region.interiors:
        return [region]
    _, ymin, _, ymax = region.bounds
    cuts = shapely.MultiLineString([[(x, ymin - 1), (x, ymax + 1)]
                                    for x in (shapely.Polygon(h).representative_point().x for h in region.interiors)])
    return [p for p in shapely.ops.split(region, cuts).geoms if isinstance(p, shapely.Polygon) and p.area > 0]
