"""SVG drawings, read by svgelements: the closed outlines of the drawing, of a layer or of one element.

Paths (lines, elliptical arcs, quadratic and cubic Béziers), rect, circle, ellipse, polygon and
the like are read with every ``transform`` applied; text and images are not read, with a note.
Each closed subpath is an outline; open ones are not read (a note says how many). Curves become an
ezdxf path, as a DXF drawing's do (:mod:`.dxf`: arcs as cubic Béziers of at most 22.5 degrees),
flattened to the chord tolerance.

Units: the file's numbers are read as written, in its user units (the ``viewBox``'s, which
drawing programs and laser cutters set to millimetres), and ``units`` says what one is; the
root's ``width`` and ``height``, which only size the picture on a screen, are not applied.
The y axis is flipped: SVG's points down the screen, the table's up (x right, y up, angles
counter-clockwise), so the part on the table looks as the drawing does on the screen, and is not
its mirror image (a mirrored part is another part).

``layer`` keeps the elements in the layer of that label (an Inkscape layer, a group with
``inkscape:groupmode="layer"``), ``object`` the element with that ``id`` (all of it, for a group).

svgelements expands each ``<use>`` into a copy of what it refers to, uses within it included, so a
few kilobytes of uses of groups of uses expand exponentially. Before it sees the file, the file's
elements are counted as it would expand them (:func:`_check_expansion`, with a bounded XML pass
that keeps no tree): at most :data:`~planner.model.cad.MAX_ENTITIES` elements, ``<use>`` nested
at most :data:`MAX_USE_DEPTH` deep, elements nested at most :data:`MAX_NESTING` deep, and
:data:`~planner.model.cad.MAX_POINTS` points of path data.
"""

from __future__ import annotations

import io
import itertools
import math
import re
from collections import Counter
from typing import TYPE_CHECKING
from xml.etree import ElementTree

from ..fields import SceneError, shown
from . import MAX_ENTITIES, MAX_POINTS, Selection, Shape, flattened, shapes_from_rings

if TYPE_CHECKING:
    import ezdxf.path
    import svgelements as svg

__all__ = ["MAX_NESTING", "MAX_USE_DEPTH", "NEEDS", "read"]

#: The libraries read imports (the cad extra's): imported there, so that this module loads without them.
NEEDS = ("svgelements", "ezdxf")

_INKSCAPE = "{http://www.inkscape.org/namespaces/inkscape}"
#: Deepest nesting of ``<use>`` (a use of a group holding a use...): drawings use symbols, seldom
#: symbols of symbols; eight levels is the DXF reader's for block references.
MAX_USE_DEPTH = 8
#: Deepest nesting of elements, uses expanded: svgelements recurses once a level and Python stops
#: near a thousand; drawing programs nest groups a few levels deep.
MAX_NESTING = 100
#: Where svgelements finds what a ``<use>`` refers to: ``href``, else ``xlink:href``.
_HREFS = ("href", "{http://www.w3.org/1999/xlink}href")
#: A number of path data or a polygon's points (SVG's grammar: ``1.5.5`` is two).
_NUMBER = re.compile(r"[-+]?(?:\d+\.?\d*|\.\d+)(?:[eE][-+]?\d+)?")
#: Bézier curves per full turn of an elliptical arc, at most 22.5 degrees each, as for DXF
#: (:mod:`.dxf`); an arc of a quarter turn (each of a circle's four) gets four.
_ARC_CURVES = 16


def read(raw: bytes, suffix: str, selection: Selection, notes: list[str]) -> list[Shape]:
    """The shapes the SVG file ``raw`` draws, in all or in ``selection``'s layer or element (module docstring)."""
    import svgelements as svg

    try:
        _check_expansion(raw, selection)
        root = svg.SVG.parse(io.BytesIO(raw), reify=True)
    except SceneError:
        raise
    except Exception as err:  # noqa: BLE001 (untrusted bytes: any failure of the parser is "not SVG")
        raise SceneError(selection.field, f"not a readable SVG file ({type(err).__name__}: {err})") from None
    if not isinstance(root, svg.SVG):
        raise SceneError(selection.field, "not a readable SVG file (no svg element)")
    # Back from the screen to the file's user units, then y up (module docstring).
    try:
        to_table = ~svg.Matrix(root.viewbox_transform or "") * svg.Matrix("scale(1, -1)")
    except ZeroDivisionError:  # svgelements divides by the viewBox's and the page's sizes
        raise SceneError(selection.field, "its viewBox, width or height is zero: the drawing has no scale") from None
    skipped: Counter[str] = Counter()
    rings, left_open, points = [], 0, 0
    for element in _chosen(root, selection):
        if isinstance(element, (svg.Text, svg.Image)):
            skipped[type(element).__name__.lower()] += 1
        if not isinstance(element, svg.Shape):
            continue
        shape = abs(svg.Path(element) * to_table)
        for sub in shape.as_subpaths():
            path, closed = _path(list(sub))
            if path is None:
                continue
            where = f"element {shown(element.id)}" if element.id else f"a {type(element).__name__.lower()}"
            flat = flattened(path, selection, where, MAX_POINTS - points)
            points += len(flat)
            if closed:
                rings.append(flat[:-1])
            else:
                left_open += 1
    if skipped:
        notes.append(f"{selection.field}: not read: {', '.join(f'{n} {kind}' for kind, n in sorted(skipped.items()))}")
    if left_open:
        notes.append(f"{selection.field}: {left_open} open subpath(s) are not read")
    return shapes_from_rings(rings, selection)


def _check_expansion(raw: bytes, selection: Selection) -> None:
    """Refuse the SVG file ``raw`` if svgelements would expand it past the module's caps (its
    docstring), before it does: one pass of the XML records each element's children, what its
    ``<use>`` refers to and how many numbers its path data or points hold; then each element's
    expansion is summed from the leaves up, each element once.

    Raises
    ------
    SceneError
        Naming the file: past a cap, or a ``<use>`` refers to an element that holds it.
    xml.etree.ElementTree.ParseError
        The bytes are not XML.
    """
    children: list[list[int]] = []
    refers: list[str | None] = []
    numbers: list[int] = []
    ids: dict[str, int] = {}
    open_: list[int] = []  # the elements the parser is inside
    for event, element in ElementTree.iterparse(io.BytesIO(raw), events=("start", "end")):
        if event == "end":
            open_.pop()
            element.clear()  # the pass keeps no tree: what it needs is in the lists
            continue
        k = len(children)
        if k == MAX_ENTITIES:
            raise SceneError(selection.field, f"holds more than {MAX_ENTITIES} elements")
        if len(open_) == MAX_NESTING:
            raise SceneError(selection.field, f"nests elements more than {MAX_NESTING} deep")
        if open_:
            children[open_[-1]].append(k)
        open_.append(k)
        children.append([])
        attributes = element.attrib
        if "id" in attributes:  # the last element of an id is the one svgelements finds
            ids[attributes["id"]] = k
        href = next((attributes[h] for h in _HREFS if h in attributes), None)
        refers.append(href[1:] if href is not None and element.tag.rpartition("}")[2] == "use" else None)
        numbers.append(_numbers(attributes))
    _expanded_sizes(children, [ids.get(r) if r is not None else None for r in refers], numbers, selection)


def _numbers(attributes: dict[str, str]) -> int:
    """How many numbers the path data (``d``) and ``points`` of an element hold, counted up to
    just past the cap (:data:`~planner.model.cad.MAX_POINTS` points, two numbers each)."""
    found = itertools.chain.from_iterable(_NUMBER.finditer(attributes.get(key, "")) for key in ("d", "points"))
    return sum(1 for _ in itertools.islice(found, 2 * MAX_POINTS + 1))


def _expanded_sizes(children: list[list[int]], refers: list[int | None], numbers: list[int],
                    selection: Selection) -> None:
    """Refuse the expansion of element 0 (the root) past the caps: ``children[k]`` are element
    ``k``'s own, ``refers[k]`` the element its ``<use>`` copies (None if none), ``numbers[k]`` the
    numbers of its own path data. Depth first without recursion (the document may nest deep);
    each total saturates just past its cap, so that no count grows with the expansion."""
    size, nesting, uses, coordinates = ([0] * len(children) for _ in range(4))
    state = [0] * len(children)  # 0 not reached, 1 on the path from the root, 2 summed
    stack = [0] if children else []
    while stack:
        k = stack[-1]
        below = children[k] + ([refers[k]] if refers[k] is not None else [])
        if state[k] == 0:
            state[k] = 1
            for j in below:
                if state[j] == 1:
                    raise SceneError(selection.field, "a <use> refers to an element that holds it (a loop)")
                if state[j] == 0:
                    stack.append(j)
            continue
        stack.pop()
        if state[k] == 2:  # reached twice before it was summed
            continue
        state[k] = 2
        size[k] = min(MAX_ENTITIES + 1, 1 + sum(size[j] for j in below))
        nesting[k] = 1 + max((nesting[j] for j in below), default=0)
        uses[k] = max([uses[j] for j in children[k]] + ([1 + uses[refers[k]]] if refers[k] is not None else [0]))
        coordinates[k] = min(2 * MAX_POINTS + 1, numbers[k] + sum(coordinates[j] for j in below))
    if size and size[0] > MAX_ENTITIES:
        raise SceneError(selection.field, f"expands to more than {MAX_ENTITIES} elements (<use> copies counted)")
    if uses and uses[0] > MAX_USE_DEPTH:
        raise SceneError(selection.field, f"nests <use> more than {MAX_USE_DEPTH} deep")
    if nesting and nesting[0] > MAX_NESTING:
        raise SceneError(selection.field, f"nests elements more than {MAX_NESTING} deep (<use> copies counted)")
    if coordinates and coordinates[0] > 2 * MAX_POINTS:
        raise SceneError(selection.field, f"holds more than {MAX_POINTS} points of path data (<use> copies counted)")


def _chosen(root: svg.SVG, selection: Selection) -> list:
    """The elements ``selection`` picks: all, those of its layer, or its element and what it holds."""
    import svgelements as svg

    if selection.name is not None:
        element = root.get_element_by_id(selection.name)
        if element is None:
            raise SceneError(selection.field, f"no element with id {shown(selection.name)}")
        return [element, *(element.select() if isinstance(element, svg.Group) else ())]
    if selection.layer is None:
        return list(root.elements())
    layers = {}
    for group in root.elements(lambda e: isinstance(e, svg.Group)):
        own = group.values.get("attributes", {})
        if own.get(f"{_INKSCAPE}groupmode") == "layer":
            layers.setdefault(own.get(f"{_INKSCAPE}label"), group)
    if selection.layer not in layers:
        known = ", ".join(sorted(shown(name) for name in layers if name)) or "none"
        raise SceneError(selection.field, f"no layer labelled {shown(selection.layer)} (layers: {known})")
    return list(layers[selection.layer].select())


def _path(segments: list) -> tuple[ezdxf.path.Path | None, bool]:
    """The subpath ``segments`` as an ezdxf path, and whether it is closed (None for a bare move)."""
    import ezdxf.path
    import svgelements as svg

    start = segments[0].end if isinstance(segments[0], svg.Move) else segments[0].start
    if start is None:  # a subpath that never says where it is ("Z" alone): nothing drawn
        return None, False
    path = ezdxf.path.Path((start.x, start.y))
    closed = False
    for segment in segments:
        end = segment.end
        if isinstance(segment, svg.Close):
            closed = True
        elif isinstance(segment, svg.CubicBezier):
            path.curve4_to((end.x, end.y), (segment.control1.x, segment.control1.y),
                           (segment.control2.x, segment.control2.y))
        elif isinstance(segment, svg.QuadraticBezier):
            path.curve3_to((end.x, end.y), (segment.control.x, segment.control.y))
        elif isinstance(segment, svg.Arc) and segment.rx and segment.ry:
            for cubic in segment.as_cubic_curves(_cubics(segment.sweep)):
                path.curve4_to((cubic.end.x, cubic.end.y), (cubic.control1.x, cubic.control1.y),
                               (cubic.control2.x, cubic.control2.y))
        elif not isinstance(segment, svg.Move):  # a line, or an arc of no radius, which is one
            path.line_to((end.x, end.y))
    if len(path) == 0:
        return None, False
    if closed and not path.is_closed:
        path.line_to(path.start)
    return path, closed or path.is_closed


def _cubics(sweep: float) -> int:
    """How many cubic Béziers an arc of ``sweep`` radians is drawn with: one per 22.5 degrees, at
    least one (a sweep a file's numbers made infinite or NaN gets a full turn's: its points are
    checked next).

    >>> _cubics(math.pi / 2), _cubics(-2 * math.pi), _cubics(0.01), _cubics(float("nan"))
    (4, 16, 1, 16)
    """
    if not math.isfinite(sweep):
        return _ARC_CURVES
    return max(1, math.ceil(_ARC_CURVES * min(abs(sweep), math.tau) / math.tau))
