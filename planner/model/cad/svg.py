"""SVG drawings, read by svgelements: the closed outlines of the drawing, of a layer or of one element.

Paths (lines, elliptical arcs, quadratic and cubic Béziers), rect, circle, ellipse, polygon and
the like are read with every ``transform`` applied; text and images are not read, with a note.
Each closed subpath is an outline; open ones are not read (a note says how many). Curves become an
ezdxf path, as a DXF drawing's do (:mod:`.dxf`: arcs as 16 cubic Béziers each), flattened to the
chord tolerance.

Units: the file's numbers are read as written, in its user units (the ``viewBox``'s, which
drawing programs and laser cutters set to millimetres), and ``units`` says what one is; the
root's ``width`` and ``height``, which only size the picture on a screen, are not applied.
The y axis is flipped: SVG's points down the screen, the table's up (x right, y up, angles
counter-clockwise), so the part on the table looks as the drawing does on the screen, and is not
its mirror image (a mirrored part is another part).

``layer`` keeps the elements in the layer of that label (an Inkscape layer, a group with
``inkscape:groupmode="layer"``), ``name`` the element with that ``id`` (all of it, for a group).
"""

from __future__ import annotations

import io
from collections import Counter

from typing import TYPE_CHECKING

import numpy as np

from ..fields import SceneError, shown
from . import MAX_POINTS, Selection, Shape, shapes_from_rings

if TYPE_CHECKING:
    import ezdxf.path
    import svgelements as svg

__all__ = ["NEEDS", "read"]

#: The libraries read imports (the cad extra's): imported there, so that this module loads without them.
NEEDS = ("svgelements", "ezdxf")

_INKSCAPE = "{http://www.inkscape.org/namespaces/inkscape}"
#: Bézier curves per elliptical arc, as for DXF (:mod:`.dxf`).
_ARC_CURVES = 16


def read(raw: bytes, suffix: str, selection: Selection, notes: list[str]) -> list[Shape]:
    """The shapes the SVG file ``raw`` draws, in all or in ``selection``'s layer or element (module docstring)."""
    import svgelements as svg

    try:
        root = svg.SVG.parse(io.BytesIO(raw), reify=True)
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
            selection.check_points(np.array([(v.x, v.y) for v in path.control_vertices()]).reshape(-1, 2), where)
            flat = np.array([(v.x, v.y) for v in path.flattening(selection.chord)]).reshape(-1, 2)
            points += len(flat)
            if points > MAX_POINTS:
                raise SceneError(selection.field, f"its curves flatten to more than {MAX_POINTS} points at this "
                                                  "chord tolerance")
            if closed:
                rings.append(flat[:-1])
            else:
                left_open += 1
    if skipped:
        notes.append(f"{selection.field}: not read: {', '.join(f'{n} {kind}' for kind, n in sorted(skipped.items()))}")
    if left_open:
        notes.append(f"{selection.field}: {left_open} open subpath(s) are not read")
    return shapes_from_rings(rings, selection)


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
            for cubic in segment.as_cubic_curves(_ARC_CURVES):
                path.curve4_to((cubic.end.x, cubic.end.y), (cubic.control1.x, cubic.control1.y),
                               (cubic.control2.x, cubic.control2.y))
        elif not isinstance(segment, svg.Move):  # a line, or an arc of no radius, which is one
            path.line_to((end.x, end.y))
    if len(path) == 0:
        return None, False
    if closed and not path.is_closed:
        path.line_to(path.start)
    return path, closed or path.is_closed
