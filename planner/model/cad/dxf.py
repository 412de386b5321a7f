"""DXF drawings, read by ezdxf: the closed outlines of a layer, or of a block.

LWPOLYLINE and POLYLINE (with bulges, which are arcs), CIRCLE, ARC, ELLIPSE, SPLINE and LINE are
read, and block references (INSERT) are expanded into what they draw. Each entity becomes an
ezdxf path; elliptical arcs are first made of 16 cubic Béziers each (at most 22.5 degrees of a
circle each, off it by less than 7e-8 of the radius), and then every path is flattened to the
chord tolerance. Closed paths are outlines; the open ones (lines, arcs, open polylines) are
joined where they meet end to end, and each closed chain is an outline too. Chains that stay open,
and text, dimensions, hatches and the like, are not read, and a note says so.

``layer`` keeps the entities on that layer (by name, in any case, as DXF names are); a block
reference on it draws its whole block. ``name`` reads the block of that name instead of the
model space, in the block's own frame.
"""

from __future__ import annotations

import io
from collections import Counter
from collections.abc import Iterator

import numpy as np
import shapely

from ..fields import SceneError, shown
from . import MAX_POINTS, Selection, Shape, shapes_from_rings

__all__ = ["MAX_ENTITIES", "NEEDS", "read"]

#: The libraries read imports (the cad extra's): imported there, so that this module loads without them.
NEEDS = ("ezdxf",)

#: The entities drawn; every other kind is skipped with a note.
_DRAWN = {"LWPOLYLINE", "POLYLINE", "LINE", "ARC", "CIRCLE", "ELLIPSE", "SPLINE"}
#: Deepest nesting of block references expanded.
_MAX_DEPTH = 8
#: Most entities read, block references expanded: a drawing of parts holds thousands; a few
#: hundred bytes of blocks of references to blocks would otherwise expand to billions.
MAX_ENTITIES = 10_000
#: Bézier curves per elliptical arc: 16 keep each within 22.5 degrees, where the curve departs
#: from the arc by less than 7e-8 of its radius (0.07 mm at the 1 km limit).
_ARC_CURVES = 16


def read(raw: bytes, suffix: str, selection: Selection, notes: list[str]) -> list[Shape]:
    """The shapes the DXF file ``raw`` draws on ``selection``'s layer or block (module docstring)."""
    import ezdxf.path
    import ezdxf.recover

    try:
        doc, _ = ezdxf.recover.read(io.BytesIO(raw))
    except Exception as err:  # noqa: BLE001 (untrusted bytes: any failure of the parser is "not DXF")
        raise SceneError(selection.field, f"not a readable DXF file ({type(err).__name__}: {err})") from None
    if selection.name is None:
        space = doc.modelspace()
    elif (space := doc.blocks.get(selection.name)) is None:
        names = sorted(b.name for b in doc.blocks if not b.name.startswith("*"))
        raise SceneError(selection.field, f"no block named {shown(selection.name)} (blocks: {', '.join(names) or 'none'})")
    entities = (e for e in space if selection.layer is None or e.dxf.layer.upper() == selection.layer.upper())
    skipped: Counter[str] = Counter()
    rings, pieces, points = [], [], 0
    for entity in _expanded(entities, 0, skipped, selection):
        try:
            path = ezdxf.path.make_path(entity, segments=_ARC_CURVES)
        except Exception as err:  # noqa: BLE001 (a malformed entity: refused rather than left out of an outline)
            raise SceneError(selection.field, f"{entity.dxftype()} #{entity.dxf.handle} cannot be drawn "
                                              f"({type(err).__name__}: {err})") from None
        for sub in path.sub_paths():
            selection.check_points(np.array([(v.x, v.y) for v in sub.control_vertices()]).reshape(-1, 2),
                                   f"{entity.dxftype()} #{entity.dxf.handle}")
            flat = np.array([(v.x, v.y) for v in sub.flattening(selection.chord)]).reshape(-1, 2)
            points += len(flat)
            if points > MAX_POINTS:
                raise SceneError(selection.field, f"its curves flatten to more than {MAX_POINTS} points at this "
                                                  "chord tolerance")
            if sub.is_closed:
                rings.append(flat[:-1])
            elif len(flat) > 1:
                pieces.append(flat)
    chained, left_open = _chains(pieces, selection.chord)
    if skipped:
        notes.append(f"{selection.field}: not read: {', '.join(f'{n} {kind}' for kind, n in sorted(skipped.items()))}")
    if left_open:
        notes.append(f"{selection.field}: {left_open} open chain(s) of lines or arcs do not close and are not read")
    return shapes_from_rings(rings + chained, selection)


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


def _chains(pieces: list[np.ndarray], chord: float) -> tuple[list[np.ndarray], int]:
    """The closed rings that the open polylines ``pieces`` form where they meet end to end (ends
    within a hundredth of ``chord`` are taken as one), and how many chains stay open."""
    if not pieces:
        return [], 0
    lines = shapely.set_precision([shapely.LineString(piece) for piece in pieces], chord / 100)
    faces, cuts, dangles, invalid = shapely.polygonize_full([shapely.union_all(lines)])
    # A loop inside another is a face of its own, so the faces' outer rings are every loop.
    rings = [np.asarray(face.exterior.coords)[:-1] for face in shapely.get_parts(faces)]
    return rings, sum(len(shapely.get_parts(g)) for g in (cuts, dangles, invalid))
