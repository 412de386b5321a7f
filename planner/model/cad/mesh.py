"""Meshes (STL, OBJ, PLY), read by trimesh: a body's projection on the table and its footprint.

The table is the plane z = lowest z of the mesh, seen from above (z up, so x and y are the
table's). A body's region is the union of its triangles projected on the table (:func:`_projected`:
a hole through the body, top to bottom, stays open; its outline is what a pusher can touch), and
its footprint the union of the triangles lying on the table: those whose three corners are within
the chord tolerance of the lowest z. The footprint is what carries the part's weight, so its
centroid is the part's default centre of friction. A mesh that touches the table only at points or
along edges (a cone on its tip, a sphere) has no footprint and is refused.

``object`` picks a body by name: an OBJ's objects (its ``o`` lines), or the bodies trimesh finds
and names in other files (``geometry_0``...); meshes have no layers.
"""

from __future__ import annotations

import io
import math

import numpy as np
import shapely

from ..fields import SceneError, shown
from . import MAX_POINTS, Selection, Shape

__all__ = ["NEEDS", "read"]

#: The libraries read imports (the cad extra's): imported there, so that this module loads without them.
NEEDS = ("trimesh",)
#: A face whose normal's z is within this of 0 is seen edge-on from above (trimesh's tolerance).
_EDGE_ON = 1e-10


def read(raw: bytes, suffix: str, selection: Selection, notes: list[str]) -> list[Shape]:
    """The bodies of the mesh file ``raw`` (of kind ``suffix``), or the one ``selection`` names (module docstring)."""
    import trimesh

    if selection.layer is not None:
        raise SceneError(selection.field, "a mesh has no layers (object picks one of its bodies)")
    # An OBJ's objects are bodies of their own, by their names; trimesh would merge them.
    split = {"split_objects": True} if suffix == ".obj" else {}
    try:
        bodies = dict(trimesh.load_scene(io.BytesIO(raw), file_type=suffix[1:], process=False, **split).geometry)
    except Exception as err:  # noqa: BLE001 (untrusted bytes: any failure of the parser is "not a mesh")
        raise SceneError(selection.field, f"not a readable {suffix[1:].upper()} file ({type(err).__name__}: "
                                          f"{err})") from None
    if selection.name is not None:
        if selection.name not in bodies:
            known = ", ".join(shown(name) for name in sorted(bodies)) or "none"
            raise SceneError(selection.field, f"no body named {shown(selection.name)} (bodies: {known})")
        bodies = {selection.name: bodies[selection.name]}
    meshes = [mesh for mesh in bodies.values() if isinstance(mesh, trimesh.Trimesh) and len(mesh.faces)]
    if sum(len(mesh.faces) for mesh in meshes) > MAX_POINTS:
        raise SceneError(selection.field, f"the mesh has more than {MAX_POINTS} triangles")
    if not meshes:
        raise SceneError(selection.field, "the file holds no triangles")
    for body in meshes:  # an OBJ's or PLY's vertices and faces are as the file writes them
        if body.vertices.shape[1:] != (3,):
            raise SceneError(selection.field, f"its vertices have {body.vertices.shape[1]} coordinates, not x, y, z")
        if (bad := body.faces[(body.faces < 0) | (body.faces >= len(body.vertices))]).size:
            raise SceneError(selection.field, f"a face refers to vertex {bad[0]}, which the mesh does not have "
                                              f"(it has {len(body.vertices)})")
    mesh = trimesh.util.concatenate(meshes)
    selection.check_points(mesh.vertices, "the mesh")
    mesh.merge_vertices()  # an STL's triangles share no vertices: joined, they form the patches projected below
    region = _projected(mesh)
    lowest = float(mesh.vertices[:, 2].min())
    on_table = np.flatnonzero(np.all(mesh.vertices[mesh.faces][:, :, 2] <= lowest + 2 * selection.chord, axis=1))
    footprint = _projected(mesh.submesh([on_table], append=True)) if len(on_table) else shapely.Polygon()
    if footprint.area <= 0:
        raise SceneError(selection.field, f"the mesh has no footprint: no face lies flat at its lowest point "
                                          f"(z = {lowest:g}), which it touches only at points or along edges")
    grid = selection.chord / 10  # far below the tolerance: no slivers of rounding
    return [Shape(part, part.intersection(footprint, grid_size=grid)) for part in shapely.get_parts(region)
            if isinstance(part, shapely.Polygon) and part.area > 0]


def _projected(mesh) -> shapely.Polygon | shapely.MultiPolygon:
    """What ``mesh`` (vertices merged) covers seen from above: the union of its patches, each a
    set of adjacent faces all turned up, or all down (a face seen edge-on covers nothing). A
    patch's triangles, projected, tile it, so their union is a coverage union, linear in them;
    one that folds over itself is no tiling, and its triangles are unioned one by one. trimesh's
    own projection needs networkx and rtree, which the cad extra does not install, for a patch
    with a hole (docs/stack.md, "CAD readers").

    >>> import trimesh
    >>> washer = trimesh.creation.annulus(r_min=5, r_max=20, height=10)  # a patch with a hole on top
    >>> round(_projected(washer).area / (np.pi * (20 ** 2 - 5 ** 2)), 2), len(_projected(washer).interiors)
    (0.99, 1)
    """
    from trimesh.graph import connected_component_labels

    up = mesh.face_normals[:, 2]
    patches = []
    for side in (up > _EDGE_ON, up < -_EDGE_ON):
        adjacency = mesh.face_adjacency[side[mesh.face_adjacency].all(axis=1)]
        labels = connected_component_labels(adjacency, node_count=len(mesh.faces))
        faces = np.flatnonzero(side)
        faces = faces[np.argsort(labels[faces], kind="stable")]
        for patch in np.split(faces, np.flatnonzero(np.diff(labels[faces])) + 1):
            triangles = shapely.polygons(mesh.vertices[mesh.faces[patch]][:, :, :2])
            patches.append(_tiled(triangles[shapely.area(triangles) > 0]))
    return shapely.make_valid(shapely.union_all(patches))


def _tiled(triangles: np.ndarray) -> shapely.Polygon | shapely.MultiPolygon:
    """The union of ``triangles``, by coverage union where they tile (no overlap: the union's
    area is theirs), else one by one."""
    try:
        union = shapely.coverage_union_all(triangles)
    except shapely.errors.GEOSException:  # edges that meet off each other's vertices
        return shapely.union_all(triangles)
    if union.is_valid and math.isclose(union.area, float(shapely.area(triangles).sum()), rel_tol=1e-9):
        return union
    return shapely.union_all(triangles)
