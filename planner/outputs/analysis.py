"""The mechanics of the pushed edge as the recording shows them: each edge's stable COR regions
(procedure STABLE's and the exact one) and the force status of sticking, in the slider frame.

An analysis costs about a tenth of a second, so it is kept in the region cache
(:class:`~planner.actions.region_cache.RegionCache`, kind ``analysis``) and computed ahead, beside
the search, by the recorder (:func:`prepare`); an edge a quarter or half turn of the part carries
onto one already analysed gets that one, turned (:func:`analysis`).
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import NamedTuple

import numpy as np
import shapely
import shapely.affinity

from mechanics import ContactConfiguration, SupportModel, contact_wrench_cone, force_status_regions

from ..actions.region_cache import RegionCache, cache_key, default_cache, edge_region, is_cached
from ..model.scene import Scene

__all__ = ["ANALYSIS_RAYS", "STATUS", "Analysis", "analysis", "prepare"]

#: Rays per sense of the sticking force-status map in ``/analysis`` (about a tenth of a second).
ANALYSIS_RAYS = 16
#: Seconds :func:`prepare` waits between looks for a newly cached region.
_POLL = 0.02
#: The force statuses drawn: possible, undetermined, impossible (Lynch 1992, §3).
STATUS = ("P", "U", "I")


class Analysis(NamedTuple):
    """What ``/analysis`` shows of one edge, in the slider frame: the window, the contact
    segment, and polygons by name ('stable', 'exact': COR regions; 'P', 'U', 'I': force status
    of sticking) and sense (1 CCW, -1 CW)."""

    window: tuple[float, float, float, float]
    contact: np.ndarray
    polygons: dict[str, dict[int, shapely.Geometry]]


def _analysis_key(scene: Scene, edge: int) -> str:
    p = scene.pusher
    return cache_key("analysis", scene.slider, edge, p.mu, p.width, scene.cf_uncertainty, rays=ANALYSIS_RAYS)


def analysis(scene: Scene, edge: int, cache: RegionCache | None = None) -> Analysis:
    """The analysis of ``edge``, kept in ``cache`` (default:
    :func:`~planner.actions.region_cache.default_cache`) beside the exact regions, so that
    :func:`prepare` can compute it ahead of :func:`~planner.outputs.recording.write_recording`: from the cache's memory, else
    from its file (the polygons as WKB), else turned from a twin edge's, else computed (0.1 s,
    with the exact region from ``cache``), and kept in both."""
    cache = default_cache() if cache is None else cache
    key = _analysis_key(scene, edge)
    found = cache.get(key) or _from_json(cache.read("analysis", key))
    if found is None:
        found = _turned_twin(scene, edge, cache) or _computed(scene, edge, cache)
        cache.write("analysis", key, {
            "window": list(found.window), "contact": found.contact.tolist(),
            "polygons": {name: {str(sense): shapely.to_wkb(g, hex=True) for sense, g in by.items()}
                         for name, by in found.polygons.items()}})
    cache.put(key, found)
    return found


def _from_json(data: object) -> Analysis | None:
    """The analysis a cache file held (``data``, its JSON, None if unread), or None if it is not one."""
    try:
        return Analysis(tuple(data["window"]), np.asarray(data["contact"], dtype=float),
                        {name: {int(sense): shapely.from_wkb(bytes.fromhex(wkb)) for sense, wkb in by.items()}
                         for name, by in data["polygons"].items()})
    except (ValueError, KeyError, TypeError, AttributeError, shapely.errors.GEOSException):
        return None


def _turned_twin(scene: Scene, edge: int, cache: RegionCache) -> Analysis | None:
    """The analysis of an edge that a quarter or half turn of the part about its CF carries onto
    ``edge`` (:attr:`mechanics.Slider.turns`), if ``cache`` has it in memory, turned with the part;
    the window, a square about the CF, turns onto itself."""
    slider = scene.slider
    for r in slider.turns:
        angle = slider.turn_angle(r)
        if abs(math.remainder(angle, math.pi / 2)) > 1e-9:
            continue
        twin = cache.get(_analysis_key(scene, (edge - r) % slider.n))
        if twin is not None:
            c, s = math.cos(angle), math.sin(angle)
            cf = tuple(slider.cf)
            return Analysis(twin.window, (twin.contact - slider.cf) @ np.array([[c, s], [-s, c]]) + slider.cf,
                            {name: {sense: shapely.affinity.rotate(g, angle, origin=cf, use_radians=True)
                                    for sense, g in by.items()} for name, by in twin.polygons.items()})
    return None


def _computed(scene: Scene, edge: int, cache: RegionCache) -> Analysis:
    """The analysis of ``edge`` from its regions and force status, the 0.1 s :func:`analysis` saves."""
    slider, p = scene.slider, scene.pusher
    window = (*(slider.cf - 4 * slider.radius).tolist(), *(slider.cf + 4 * slider.radius).tolist())
    # The exact region whatever the plan used (cached): the view compares it with STABLE's.
    polygons = {"stable": edge_region(slider, edge, p.mu, p.width, "stable").cor_polygons(window),
                "exact": edge_region(slider, edge, p.mu, p.width, "exact", scene.cf_uncertainty,
                                     cache=cache).cor_polygons(window)}
    config = ContactConfiguration.slider_edge(slider, edge, p.mu, p.width)
    support = SupportModel.of_slider(slider, cf_radius=scene.cf_uncertainty)  # as the plan's regions
    status = force_status_regions(contact_wrench_cone(config, "ss"), support, window,
                                  rays=ANALYSIS_RAYS, steps=6, refinements=0)
    polygons |= {label: {sense: status[sense][label] for sense in (1, -1)} for label in STATUS}
    return Analysis(window, np.asarray(config.points, dtype=float), polygons)


def prepare(scene: Scene, wait: Callable[[float], bool], cache: RegionCache | None = None) -> None:
    """Compute ahead of :func:`~planner.outputs.recording.write_recording`, in this process, the analysis of each allowed
    edge of each part, as soon as its stable region is in ``cache`` (default:
    :func:`~planner.actions.region_cache.default_cache`), until ``wait(seconds)`` (which may wait
    that long) says a plan has come; the first pushed edge is one of them.
    :mod:`planner.outputs.recorder` runs this beside the search, which caches the regions of a new
    part first, and then writes the recording with the same cache."""
    p = scene.pusher
    # Each part's edges, on its own scene (as the recording draws a part of several, alone).
    pending = [(scene.move_scene(part.name, scene.starts, others=False), e) for part in scene.parts for e in part.edges]
    while pending and not wait(0.0):
        ready = [k for k, (one, e) in enumerate(pending)
                 if is_cached(one.slider, e, p.mu, p.width, "exact", one.cf_uncertainty, cache)]
        if not ready:
            if wait(_POLL):
                return
            continue
        analysis(*pending.pop(ready[0]), cache)
