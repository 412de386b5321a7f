"""Kinematic analysis of multiple-contact pushing (Lynch 1992, §2; docs/mechanics.md, "Kinematic analysis").

**Reuleaux's method (§2.1).** Let ``rho`` be the slider's twist *relative to the pusher*. The
slider point at contact ``i`` moves relative to the pusher with ``u_i = v + omega k x p_i``; with
the contact's inward normal ``n_i`` and tangent ``t_i``:

* ``s`` (sticking): ``u_i = 0``, the relative COR is the contact point;
* ``r`` / ``l`` (sliding right / left): ``u_i . n_i = 0`` and ``u_i . t_i > 0`` / ``< 0``, the
  relative COR is elsewhere on the contact normal;
* ``f`` (breaking free): ``u_i . n_i > 0``; ``< 0`` would penetrate the pusher.

So a CCW relative COR must lie left of every contact normal it does not lie on, a CW one right of
it (the paper's rule). ``u_i . n_i = a_i . rho`` with ``a_i`` the wrench of a unit normal force at
``p_i``, and ``u_i . t_i = b_i . rho`` likewise: every label is a linear condition, so the relative
twists of a *contact mode* (one label per contact) form a polyhedral cone, open where the labels
are strict.

**Positive combination (§2.2).** In the support plane the slider moves with
``V_s = a V_p + rho``, ``a > 0``: a strictly positive combination of the pusher's twist ``V_p`` and
a relative twist. In COR space this is the rule of fig. 6: two CORs of the same sense combine to
the open segment between them, CORs of opposite senses to the two outer rays of their line (the
sense flipping at infinity, where the motion is a translation). The slider twists of a mode are
the cone spanned by ``V_p`` and the mode's relative cone, without its boundary.

The all-breaking mode (``f...f``) carries no contact force, so no quasi-static motion: it is left
out unless asked for (§2.3).
"""

from __future__ import annotations

from itertools import product

import numpy as np
from numpy.typing import ArrayLike

from .cones import Cone
from .contacts import ContactConfiguration
from .wrenches import point_wrench

__all__ = ["contact_modes", "kinematic_cone", "kinematic_cones", "modes_of_motion", "relative_cone", "relative_mode"]


def _velocity_rows(config: ContactConfiguration) -> tuple[np.ndarray, np.ndarray]:
    """Rows ``a_i``, ``b_i`` with ``a_i . rho = u_i . n_i`` and ``b_i . rho = u_i . t_i``."""
    return point_wrench(config.points, config.normals), point_wrench(config.points, config.tangents)


def _mode_rows(config: ContactConfiguration, mode: str) -> tuple[np.ndarray, np.ndarray]:
    """Rows ``c`` with ``c . rho >= 0`` describing the closed relative cone of ``mode``, and the
    mask of the rows that must hold strictly."""
    a, b = _velocity_rows(config)
    rows, strict = [], []
    for label, ai, bi in zip(config.check_mode(mode), a, b):
        if label == "f":
            rows += [ai]
            strict += [True]
            continue
        rows += [ai, -ai]  # on the normal: no normal velocity
        strict += [False, False]
        if label == "s":
            rows += [bi, -bi]
            strict += [False, False]
        else:
            rows += [bi if label == "r" else -bi]
            strict += [True]
    return np.array(rows), np.array(strict)


def relative_mode(config: ContactConfiguration, relative_twist: ArrayLike, tol: float = 1e-9) -> str | None:
    """The contact mode of a twist of the slider relative to the pusher, ``None`` if it penetrates.

    ``tol`` is relative to the largest contact-point speed.

    Examples
    --------
    Bottom face of a block on ``[-1, 1]``, pushed up. A CCW relative COR at the left end point
    sticks there and lifts the right end (``sf``). A CW relative COR at ``(1, 2)``, on the right
    end's normal, moves that end left along the pusher (``l``) and lifts the left end (``f``).

    >>> edge = ContactConfiguration.edge([-1, 0], [1, 0], [0, 1], mu=0.5)
    >>> from mechanics.twist import cor_to_twist
    >>> relative_mode(edge, cor_to_twist([-1, 0], 1)), relative_mode(edge, cor_to_twist([1, 2], -1))
    ('sf', 'fl')
    >>> relative_mode(edge, cor_to_twist([-1, 0], -1)) is None  # the right end would dig in
    True
    """
    a, b = _velocity_rows(config)
    rho = np.asarray(relative_twist, dtype=float)
    un, ut = a @ rho, b @ rho
    eps = tol * max(float(np.max(np.hypot(un, ut))), 1e-300)
    if np.any(un < -eps):
        return None
    labels = np.where(un > eps, "f", np.where(np.abs(ut) <= eps, "s", np.where(ut > 0, "r", "l")))
    return "".join(labels)


def relative_cone(config: ContactConfiguration, mode: str) -> Cone:
    """The relative twists of ``mode`` (closed: its boundary belongs to neighbouring modes).

    >>> edge = ContactConfiguration.edge([-1, 0], [1, 0], [0, 1], mu=0.5)
    >>> relative_cone(edge, "rr").generators.round(12).tolist()  # sliding right along the face
    [[1.0, 0.0, 0.0]]
    """
    rows, _ = _mode_rows(config, mode)
    return Cone.from_rows(rows)


def _is_feasible(config: ContactConfiguration, mode: str) -> bool:
    """Whether some relative twist has exactly the labels of ``mode``.

    In the relative interior of the closed cone every row is strict unless it vanishes on the whole
    cone, so the mode exists iff no strict row vanishes on all the generators.
    """
    rows, strict = _mode_rows(config, mode)
    cone = Cone.from_rows(rows)
    if not strict.any():
        return True
    if len(cone.generators) == 0:
        return False
    unit = rows[strict] / np.linalg.norm(rows[strict], axis=1, keepdims=True)
    return bool(np.all(np.max(unit @ cone.generators.T, axis=1) > 1e-9))


def contact_modes(config: ContactConfiguration, include_free: bool = False) -> tuple[str, ...]:
    """The kinematically possible contact modes, ``f...f`` only if ``include_free``.

    >>> edge = ContactConfiguration.edge([-1, 0], [1, 0], [0, 1], mu=0.5)
    >>> contact_modes(edge)
    ('ss', 'sf', 'rr', 'rf', 'll', 'lf', 'fs', 'fr', 'fl')
    """
    free = "f" * len(config)
    return tuple(
        mode
        for mode in map("".join, product("srlf", repeat=len(config)))
        if (include_free or mode != free) and _is_feasible(config, mode)
    )


def kinematic_cone(config: ContactConfiguration, mode: str, pusher_twist: ArrayLike) -> Cone:
    """The slider twists (support frame) of ``mode`` when the pusher moves with ``pusher_twist``.

    The closed cone spanned by the pusher twist and the mode's relative cone; the mode's motions
    are its relative interior (``contains(..., interior=True)``), so regions of different modes
    meet on boundaries, all at the pusher's own COR (§2.3). For drawing, ``cor_region(sense,
    window)`` gives the COR region per rotation sense.

    Examples
    --------
    The block's face pushed straight up (a COR at infinity). Pivoting about the left end (``sf``)
    adds CCW rotations about ``(-1, 0)``: the slider's CORs fill the ray ``x < -1`` of the x-axis,
    the outer part of the line from the pivot to the pusher's COR at infinity.

    >>> edge = ContactConfiguration.edge([-1, 0], [1, 0], [0, 1], mu=0.5)
    >>> cone = kinematic_cone(edge, "sf", [0, 1, 0])
    >>> cone.cor_region(1, (-4, -4, 4, 4)).normalize().wkt
    'LINESTRING (-4 0, -1 0)'
    >>> cone.contains([[0, 2, 1], [0, 1, 1]], interior=True).tolist()  # CORs (-2, 0), (-1, 0)
    [True, False]
    """
    relative = relative_cone(config, mode)
    return Cone.from_generators(np.vstack([np.asarray(pusher_twist, dtype=float), relative.generators]))


def kinematic_cones(config: ContactConfiguration, pusher_twist: ArrayLike) -> dict[str, Cone]:
    """:func:`kinematic_cone` of every force-carrying contact mode, by mode (fig. 7).

    >>> edge = ContactConfiguration.edge([-1, 0], [1, 0], [0, 1], mu=0.5)
    >>> cones = kinematic_cones(edge, [0, 1, 0])
    >>> [mode for mode, cone in cones.items() if cone.dimension == 3]  # the others are thin
    ['rf', 'lf', 'fr', 'fl']
    """
    return {mode: kinematic_cone(config, mode, pusher_twist) for mode in contact_modes(config)}


def modes_of_motion(
    config: ContactConfiguration, pusher_twist: ArrayLike, slider_twist: ArrayLike, tol: float = 1e-9
) -> tuple[str, ...]:
    """The force-carrying contact modes under which the slider can move with ``slider_twist``.

    Examples
    --------
    The face pushed up: moving with the pusher is ``ss`` only (§2.3); turning CCW about
    ``(-2, 0)`` is pivoting about the left end.

    >>> edge = ContactConfiguration.edge([-1, 0], [1, 0], [0, 1], mu=0.5)
    >>> modes_of_motion(edge, [0, 1, 0], [0, 1, 0]), modes_of_motion(edge, [0, 1, 0], [0, 2, 1])
    (('ss',), ('sf',))
    """
    cones = kinematic_cones(config, pusher_twist)
    return tuple(mode for mode, cone in cones.items() if cone.contains(slider_twist, interior=True, tol=tol))
