"""DXF drawings, read by ezdxf: the closed outlines of a layer, or of a block.

LWPOLYLINE and POLYLINE (with bulges, which are arcs), CIRCLE, ARC, ELLIPSE, SPLINE and LINE are
read, and block references (INSERT) are expanded into what they draw. Each entity becomes an
ezdxf path; elliptical arcs are first made of 16 cubic Béziers each (at most 22.5 degrees of a
circle each, off it by less than 7e-8 of the radius), and then every path is flattened to the
chord tolerance. Closed paths are outlines; the open ones (lines, arcs, open polylines) are
joined where they meet end to end (:mod:`.chains`), and each closed chain is an outline too.
Chains that stay open, and text, dimensions, hatches and the like, are not read, and a note says so.

``layer`` keeps the entities on that layer (by name, in any case, as DXF names are); a block
reference on it draws its whole block. ``object`` reads the block of that name instead of the
model space, in the block's own frame.

Only ASCII DXF is read: a binary DXF is refused, saying so. What ezdxf repairs as it reads (a
number it cannot read, taken as the number it finds in it) is noted. A spline through fit points is
interpolated by ezdxf with a dense matrix (memory and time grow with the square of its points:
20,000 took 9.2 GB), so a spline may have at most :data:`MAX_FIT_POINTS` of them, and the splines
of a file :data:`MAX_FIT_POINTS_IN_ALL` and :data:`~planner.model.cad.MAX_POINTS` control points in
all, before any is drawn.
"""

from __future__ import annotations

import io
import re
from collections import Counter
from collections.abc import Iterator

from ..fields import SceneError, counted, shown
from . import MAX_ENTITIES, MAX_POINTS, Selection, Shape, flattened, shapes_from_rings
from .chains import chains

__all__ = ["MAX_FIT_POINTS", "MAX_FIT_POINTS_IN_ALL", "NEEDS", "read"]

#: The libraries read imports (the cad extra's): imported there, so that this module loads without them.
NEEDS = ("ezdxf",)

#: The entities drawn; every other kind is skipped with a note.
_DRAWN = {"LWPOLYLINE", "POLYLINE", "LINE", "ARC", "CIRCLE", "ELLIPSE", "SPLINE"}
#: Deepest nesting of block references expanded.
_MAX_DEPTH = 8
#: Most fit points of one spline: ezdxf's interpolation through 1,000 takes 23 MB and 0.05 s
#: here, and grows with their square. Ten such splines in all keep a file within half a second.
MAX_FIT_POINTS = 1_000
MAX_FIT_POINTS_IN_ALL = 10 * MAX_FIT_POINTS
#: A kind of entity as DXF names them (TEXT, 3DFACE, ACAD_PROXY_ENTITY), and how many kinds a note lists.
_PLAIN_KIND = re.compile(r"[A-Z0-9_]{1,40}")
_LISTED = 6
#: How a binary DXF file begins (AutoCAD's sentinel); ezdxf's reader takes ASCII only.
_BINARY = b"AutoCAD Binary DXF"
#: Bézier curves per elliptical arc: 16 keep each within 22.5 degrees, where the curve departs
#: from the arc by less than 7e-8 of its radius (0.07 mm at the 1 km limit).
_ARC_CURVES = 16


def read(raw: bytes, suffix: str, selection: Selection, notes: list[str]) -> list[Shape]:
    """The shapes the DXF file ``raw`` draws on ``selection``'s layer or block (module docstring)."""
    import ezdxf.path
    import ezdxf.recover

    if raw.startswith(_BINARY):
        raise SceneError(selection.field, "a binary DXF file, which is not read: save it as ASCII DXF")
    try:
        doc, auditor = ezdxf.recover.read(io.BytesIO(raw))
    except Exception as err:  # noqa: BLE001 (untrusted bytes: any failure of the parser is "not DXF")
        raise SceneError(selection.field, f"not a readable DXF file ({type(err).__name__}: {err})") from None
    if auditor.errors:  # values it could not read, taken as what it found in them: the drawing may differ
        notes.append(f"{selection.field}: ezdxf repaired {counted(len(auditor.errors), 'error')} of the file "
                     f"(the first: {shown(auditor.errors[0].message)})")
    if selection.name is None:
        space = doc.modelspace()
    elif (space := doc.blocks.get(selection.name)) is None:
        names = sorted(b.name for b in doc.blocks if not b.name.startswith("*"))
        raise SceneError(selection.field, f"no block named {shown(selection.name)} (blocks: {', '.join(names) or 'none'})")
    entities = (e for e in space if selection.layer is None or e.dxf.layer.upper() == selection.layer.upper())
    skipped: Counter[str] = Counter()
    rings, pieces, points = [], [], 0
    spline_points: Counter[str] = Counter()  # fit and control points of the splines so far
    for entity in _expanded(entities, 0, skipped, selection):
        # A block reference's entities are copies without handles: named by their kind alone.
        what = f"{entity.dxftype()} #{entity.dxf.handle}" if entity.dxf.handle else f"a {entity.dxftype()} of a block"
        if entity.dxftype() == "SPLINE":
            _count_spline(entity, what, spline_points, selection)
        try:
            path = ezdxf.path.make_path(entity, segments=_ARC_CURVES)
        except Exception as err:  # noqa: BLE001 (a malformed entity: refused rather than left out of an outline)
            raise SceneError(selection.field, f"{what} cannot be drawn ({type(err).__name__}: {err})") from None
        for sub in path.sub_paths():
            flat = flattened(sub, selection, what, MAX_POINTS - points)
            points += len(flat)
            if sub.is_closed:
                rings.append(flat[:-1])
            elif len(flat) > 1:
                pieces.append(flat)
    chained, left_open = chains(pieces, selection.chord)
    if skipped:
        notes.append(f"{selection.field}: not read: {_kinds(skipped)}")
    if left_open:
        notes.append(f"{selection.field}: {left_open} open chain(s) of lines or arcs do not close and are not read")
    return shapes_from_rings(rings + chained, selection)


def _count_spline(spline, what: str, counted: Counter[str], selection: Selection) -> None:
    """Add ``spline``'s fit and control points to ``counted``, refusing more than the module's
    caps (its docstring) before ezdxf draws it."""
    fit, control = spline.fit_point_count(), spline.control_point_count()
    if fit > MAX_FIT_POINTS:
        raise SceneError(selection.field, f"{what} has {fit} fit points, more than {MAX_FIT_POINTS} (a spline "
                                          "through them costs their square)")
    counted.update(fit=fit, control=control)
    if counted["fit"] > MAX_FIT_POINTS_IN_ALL:
        raise SceneError(selection.field, f"its splines have more than {MAX_FIT_POINTS_IN_ALL} fit points in all")
    if counted["control"] > MAX_POINTS:
        raise SceneError(selection.field, f"its splines have more than {MAX_POINTS} control points in all")


def _kinds(skipped: Counter[str]) -> str:
    """The kinds of entity ``skipped`` counts, as a note lists them: at most :data:`_LISTED`, each
    as its name if it is a plain DXF name (the file names them: one could be a terminal's escape
    sequence, or a kilobyte long), else quoted from its first 20 characters.

    >>> _kinds(Counter({"TEXT": 2, "HATCH": 1, "\x1b[31m": 1}))
    "1 '\\\\x1b[31m', 1 HATCH, 2 TEXT"
    """
    listed = [f"{n} {kind if _PLAIN_KIND.fullmatch(kind) else shown(kind[:20])}" for kind, n in sorted(skipped.items())]
    more = len(listed) - _LISTED
    return ", ".join(listed[:_LISTED]) + (f" and {more} more kinds" if more > 0 else "")


def _expanded(entities: Iterator, depth: int, skipped: Counter[str], selection: Selection,
              seen: list[int] | None = None) -> Iterator:
    """The drawn entities of ``entities``, block references replaced by what they draw; skipped
    kinds are counted in ``skipped``, and more than :data:`MAX_ENTITIES` in all are refused."""
    seen = [0] if seen is None else seen  # entities visited, shared by the nested calls
    for entity in entities:
        seen[0] += 1
        if seen[0] > MAX_ENTITIES:
            raise SceneError(selection.field, f"draws more than {MAX_ENTITIES} entities (block references expanded)")
        kind = entity.dxftype()
        if kind == "INSERT" and depth < _MAX_DEPTH:
            yield from _expanded(entity.virtual_entities(), depth + 1, skipped, selection, seen)
        elif kind in _DRAWN:
            yield entity
        else:
            skipped[kind] += 1
