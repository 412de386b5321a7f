"""Each edge's stable region for planning, computed once per part.

Procedure STABLE is a closed form; the exact region (:mod:`mechanics.exact_region`) costs about a
tenth of a second of certified linear programmes per edge. It depends only on the part, the edge,
the friction and the pusher's width, so a :class:`RegionCache` keeps it: in memory (the
:data:`MEMORY_SIZE` items used last, so a process planning many parts stays bounded) and on disk
across runs, a JSON file per region in the cache's folder, named by a hash of everything it
depends on (:func:`cache_key`), written atomically. A file that cannot be read or written is
ignored: the region is then computed again, never guessed. The recording's analyses
(:mod:`planner.outputs.recording`) are kept in the same cache, as another kind of file.

Every function here takes the cache to use as ``cache``; without one, they share
:func:`default_cache`, one per process, in the folder the environment names
(:func:`cache_folder`). Passing a cache is for a caller that wants its own: a test's empty
folder, or a region computation of its own (:class:`RegionCache`'s ``compute``).

:func:`compute_regions` computes several edges' regions at once, one process per core: the edges
are independent, and a cold run of a part otherwise waits for each in turn. The processes are
forked, so they start in milliseconds with everything already imported (spawning would import
numpy, shapely and the rest again, which costs about as much as a region); they run only
numpy and shapely code, never OMPL's. The regions come back pickled, bit for bit the ones this
process would compute, and this process alone writes the cache.
"""

from __future__ import annotations

import hashlib
import json
import os
import queue
import signal
import time
import weakref
from collections import OrderedDict
from collections.abc import Callable, Sequence
from dataclasses import replace
from pathlib import Path
from typing import Any

import numpy as np
import shapely

from mechanics import DeadlineExceeded, ExactRegion, Slider, StableRegion, exact_region, stable_region

from ..model.fields import SceneError
from ..model.files import write_atomic
from ..model.json_file import read_json
from ..model.processes import cores, die_with_parent, fork_context
from ..model.stop import quiet_child, signals_blocked

__all__ = ["MEMORY_SIZE", "RegionCache", "cache_folder", "cache_key", "compute_regions", "default_cache", "set_default_cache",
           "edge_region", "is_cached", "regions_held"]

#: Bump when the exact region's construction (or the recording's analysis) changes, so old cache
#: files are not used. 3: the support LPs by a batched simplex (its duals can differ where the LP
#: is degenerate). 4: the adaptive trace without a safety margin (larger regions), and the gap
#: bound kept with each region. 5: a finer trace and a third certificate level (larger still).
_VERSION = 5

#: Items a :class:`RegionCache` keeps in memory unless told otherwise: every region and analysis
#: of a 200-edged part twice over, a few megabytes. An item dropped is read again from its file.
MEMORY_SIZE = 1024
#: Largest cache file read: a region's polygon of some thousands of vertices, or an analysis.
MAX_FILE = 10_000_000


class RegionCache:
    """Exact regions, and other items named by :func:`cache_key`, in memory and in a folder.

    Parameters
    ----------
    folder : str or Path
        Where the files are kept between runs, ``<kind>-<key>.json``; made when the first is
        written. One that cannot be made or written costs only time: the next run computes again.
    size : int
        The most items kept in memory (:data:`MEMORY_SIZE`); the least recently used go first.
    compute : callable
        What computes a missing exact region, called as :func:`mechanics.exact_region` (the
        default): a test's may refuse, or note who called it. :func:`compute_regions` calls it in
        forked workers, so it must pickle (a module-level function, or a partial of one).

    Examples
    --------
    >>> cache = RegionCache("/nonexistent", size=2)
    >>> cache.put("a", 1); cache.put("b", 2); cache.get("a"); cache.put("c", 3)
    1
    >>> cache.get("b"), cache.get("a"), cache.get("c")   # b was the least recently used
    (None, 1, 3)
    """

    def __init__(self, folder: str | Path, size: int = MEMORY_SIZE, compute: Callable[..., ExactRegion] = exact_region):
        self.folder, self.size, self.compute = Path(folder), size, compute
        self._memory: OrderedDict[str, Any] = OrderedDict()

    def get(self, key: str) -> Any | None:
        """The item kept in memory as ``key`` (now the most recently used), or None."""
        item = self._memory.get(key)
        if item is not None:
            self._memory.move_to_end(key)
        return item

    def put(self, key: str, item: Any) -> None:
        """Keep ``item`` in memory as ``key``, dropping the least recently used beyond :attr:`size`."""
        self._memory[key] = item
        self._memory.move_to_end(key)
        while len(self._memory) > self.size:
            self._memory.popitem(last=False)

    def holds(self, kind: str, key: str) -> bool:
        """Whether ``key`` is in memory or has a file (which may yet turn out unreadable)."""
        return key in self._memory or self._path(kind, key).is_file()

    def read(self, kind: str, key: str) -> Any | None:
        """The JSON in ``key``'s file, or None if it has none or the file is not JSON (cut short,
        say); the caller checks that the JSON is what it wrote."""
        try:
            return read_json(self._path(kind, key), "cache", MAX_FILE)
        except SceneError:  # missing, unreadable, too large or too deep, not JSON
            return None

    def write(self, kind: str, key: str, data: Any) -> None:
        """Write ``data`` as JSON to ``key``'s file atomically, or nothing if the folder cannot be
        written (a read-only home: the next run computes it again)."""
        path = self._path(kind, key)
        try:
            path.parent.mkdir(parents=True, exist_ok=True)
            write_atomic(path, json.dumps(data))
        except OSError:
            pass

    def _path(self, kind: str, key: str) -> Path:
        return self.folder / f"{kind}-{key}.json"


def cache_folder() -> Path:
    """Where :func:`default_cache` keeps its files: ``$STABLEPUSH_CACHE``, else
    ``$XDG_CACHE_HOME/stablepush``, else ``~/.cache/stablepush``."""
    if os.environ.get("STABLEPUSH_CACHE"):
        return Path(os.environ["STABLEPUSH_CACHE"])
    return Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "stablepush"


#: The process's default cache (:func:`default_cache`), made on first use; :func:`set_default_cache` replaces it.
_default: RegionCache | None = None


def default_cache() -> RegionCache:
    """The cache of every call given none: one per process, so the planner, the queries and the
    recording share what each computed. It is made on first use, in :func:`cache_folder` as the
    environment says then (a later change is not seen), of :data:`MEMORY_SIZE` items, computing
    with :func:`mechanics.exact_region`; a process forked later (the recorder) has a copy. The one
    process-wide default of the planner: :func:`set_default_cache` replaces it."""
    global _default
    if _default is None:
        _default = RegionCache(cache_folder())
    return _default


def set_default_cache(cache: RegionCache | None) -> RegionCache | None:
    """Make ``cache`` the process's default (None: a new one, made from the environment at its next
    use), and return the one it replaces (None if none was made yet), to put back later.

    >>> mine = RegionCache("/tmp/stablepush-doctest-cache")
    >>> before = set_default_cache(mine)
    >>> default_cache() is mine
    True
    >>> set_default_cache(before) is mine
    True
    """
    global _default
    before, _default = _default, cache
    return before


def cache_key(kind: str, slider: Slider, edge: int, mu: float, width: float | None, cf_radius: float,
              **more) -> str:
    """The name of a cache item of ``kind`` for one edge: a hash of everything it depends on
    (and of :data:`_VERSION`, so a change of the mechanics leaves old files unused)."""
    spec = {"kind": kind, "version": _VERSION, "part": _part_digest(slider), "edge": int(edge), "mu": float(mu),
            "width": None if width is None else float(width), "cf_radius": float(cf_radius)} | more
    return hashlib.sha256(json.dumps(spec, sort_keys=True).encode()).hexdigest()[:32]


_DIGESTS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _part_digest(slider: Slider) -> str:
    """A hash of the part's vertices and CF, made once per part: a key then costs the same for a
    part of a thousand vertices as for a square (and a thousand edges ask for keys)."""
    if slider not in _DIGESTS:
        part = {"vertices": slider.vertices.tolist(), "cf": slider.cf.tolist()}
        _DIGESTS[slider] = hashlib.sha256(json.dumps(part).encode()).hexdigest()
    return _DIGESTS[slider]


def _key(slider: Slider, edge: int, mu: float, width: float | None, cf_radius: float) -> str:
    return cache_key("exact", slider, edge, mu, width, cf_radius)


def _region(data: object, stable: StableRegion, cf_radius: float) -> ExactRegion | None:
    """The region a cache file held (``data``, its JSON, None if unread), or None if it is not one."""
    try:
        polygon = shapely.Polygon(np.asarray(data["polygon"], dtype=float))
        centre = np.asarray(data["centre"], dtype=float)
        gap = float(data["gap"])
    except (ValueError, KeyError, TypeError):
        return None
    if not polygon.is_valid or polygon.area <= 0 or centre.shape != (2,) or gap < 0:
        return None
    return ExactRegion(stable, polygon, centre, cf_radius, gap)


def is_cached(slider: Slider, edge: int, mu: float, width: float | None = None, method: str = "exact",
              cf_radius: float = 0.0, cache: RegionCache | None = None) -> bool:
    """Whether :func:`edge_region` would answer from ``cache`` (default: :func:`default_cache`)
    without computing an exact region (a file that turns out unreadable is computed all the same)."""
    if method == "stable" or stable_region(slider, edge, mu, width).is_empty:
        return True
    cache = default_cache() if cache is None else cache
    return any(cache.holds("exact", key) for key in _keys_alike(slider, edge, mu, width, cf_radius))


def regions_held(slider: Slider, edges: Sequence[int], mu: float, width: float | None = None, cf_radius: float = 0.0,
                 cache: RegionCache | None = None) -> dict[str, ExactRegion]:
    """The exact regions of ``edges`` (and of their twins, :func:`_twin`) that ``cache`` (default:
    :func:`default_cache`) holds in memory, by key: what another process planning this part needs
    to be spared computing them (it :meth:`~RegionCache.put` s them into its own cache; the keys
    say what each region depends on, so one given for another part or friction is never used).

    >>> block = Slider([[-0.05, 0.0], [0.05, 0.0], [0.05, 0.06], [-0.05, 0.06]])
    >>> cache = RegionCache("/nonexistent")
    >>> held = regions_held(block, [0], 0.5, 0.08, cache=cache)
    >>> _ = edge_region(block, 0, 0.5, 0.08, cache=cache)
    >>> len(held), len(regions_held(block, [0], 0.5, 0.08, cache=cache))
    (0, 1)
    """
    cache = default_cache() if cache is None else cache
    keys = dict.fromkeys(key for edge in edges for key in _keys_alike(slider, edge, mu, width, cf_radius))
    return {key: region for key in keys if (region := cache.get(key)) is not None}


def _twin(slider: Slider, edge: int) -> int:
    """The lowest-numbered edge that a turn of the part (:attr:`mechanics.Slider.turns`) carries
    onto ``edge`` (``edge`` itself, if none): the one computed for all of them.

    >>> square = Slider([[-1, -1], [1, -1], [1, 1], [-1, 1]])
    >>> [_twin(square, e) for e in range(4)], _twin(Slider([[0, 0], [2, 0], [0, 1]]), 2)
    ([0, 0, 0, 0], 2)
    """
    # The turns are a group (two symmetries make a third): the multiples of the least one, d.
    return edge % (slider.turns[0] if slider.turns else slider.n)


def _keys_alike(slider: Slider, edge: int, mu: float, width: float | None, cf_radius: float) -> list[str]:
    """The cache keys of ``edge`` and of its twin (:func:`_twin`): both have the same region."""
    return [_key(slider, e, mu, width, cf_radius) for e in dict.fromkeys((edge, _twin(slider, edge)))]


def _known(cache: RegionCache, slider: Slider, edge: int, mu: float, width: float | None, cf_radius: float,
           stable: StableRegion) -> ExactRegion | None:
    """The exact region of ``edge`` from memory or disk, or else of an edge a turn of the part
    carries onto it: that one's section of the push plane, which is this one's (each edge's push
    plane is drawn in its own frame, and the turn carries part, CF, contact and pusher along)."""
    for key in _keys_alike(slider, edge, mu, width, cf_radius):
        found = cache.get(key) or _region(cache.read("exact", key), stable, cf_radius)
        if found is not None:
            return replace(found, stable=stable)
    return None


def edge_region(slider: Slider, edge: int, mu: float, width: float | None = None, method: str = "exact",
                cf_radius: float = 0.0, deadline: float | None = None,
                cache: RegionCache | None = None) -> StableRegion | ExactRegion:
    """The ``method`` (``'stable'`` or ``'exact'``) stable region of ``edge``, kept in ``cache``
    (default: :func:`default_cache`) as above; ``cf_radius`` (exact only) makes it hold for every
    CF within that distance of the slider's.

    Raises
    ------
    SceneError
        For ``method='stable'`` with ``cf_radius > 0``: procedure STABLE assumes a known CF.
    mechanics.DeadlineExceeded
        When an exact region must be computed and is not done by ``deadline`` (a
        :func:`time.perf_counter` time); nothing is cached then.
    """
    if method == "stable" and cf_radius > 0:
        raise SceneError("planner.regions", "procedure STABLE assumes a known CF; slider.cf_uncertainty needs "
                                            "the exact regions")
    stable = stable_region(slider, edge, mu, width)
    if method == "stable" or stable.is_empty:
        return stable
    cache = default_cache() if cache is None else cache
    key = _key(slider, edge, mu, width, cf_radius)
    region = cache.get(key) or _known(cache, slider, edge, mu, width, cf_radius, stable)
    if region is None:
        region = cache.compute(slider, edge, mu, width, cf_radius=cf_radius, deadline=deadline)
        _keep(cache, key, region)
    else:
        cache.put(key, region)
    return region


def _keep(cache: RegionCache, key: str, region: ExactRegion) -> None:
    """Keep a freshly computed region in memory and, unless it is degenerate, on disk."""
    cache.put(key, region)
    polygon, centre = region.section()
    if isinstance(polygon, shapely.Polygon) and polygon.area > 0:  # a degenerate one is cheap: not stored
        cache.write("exact", key, {"polygon": np.asarray(polygon.exterior.coords).tolist(), "centre": centre.tolist(),
                                   "gap": region.gap})


def compute_regions(slider: Slider, edges: Sequence[int], mu: float, width: float | None = None,
                    cf_radius: float = 0.0, deadline: float | None = None,
                    progress: Callable[[int, int], None] | None = None,
                    workers: int | None = None, cache: RegionCache | None = None) -> dict[int, ExactRegion]:
    """Compute the exact regions of ``edges`` (whatever the cache holds) with ``cache``'s
    ``compute``, up to ``workers`` at a time (default: one per core, at most one per edge) in
    forked processes, and keep them in ``cache`` (default: :func:`default_cache`). Of edges that a
    turn of the part carries onto one another (:attr:`mechanics.Slider.turns`), only the lowest
    numbered (:func:`_twin`) is computed: the others have its region.

    Edges are begun in order, each as soon as a worker is free, ``progress(k, n)`` being called
    just before the ``k``-th of the ``n`` computed is begun. ``deadline`` (a :func:`time.perf_counter`
    time, the same clock in every process) abandons the regions still running when it passes
    and skips those not begun: they are left out of the answer, and nothing is cached for them.

    Examples
    --------
    >>> block = Slider([[-0.05, 0.0], [0.05, 0.0], [0.05, 0.06], [-0.05, 0.06]])
    >>> sorted(compute_regions(block, [0, 2], 0.5, 0.08))
    [0, 2]
    >>> compute_regions(block, [0, 2], 0.5, 0.08, deadline=time.perf_counter())
    {}
    """
    cache = default_cache() if cache is None else cache
    first = list(dict.fromkeys(_twin(slider, edge) for edge in edges))
    workers = min(len(first), cores() if workers is None else workers)
    out: dict[int, ExactRegion] = {}
    with _workers(workers) as pool:
        waiting, running = list(first), 0
        while waiting or running:
            while waiting and running < workers and (deadline is None or time.perf_counter() <= deadline):
                edge = waiting.pop(0)
                if progress is not None:
                    progress(len(first) - len(waiting), len(first))
                pool.submit(edge, cache.compute, slider, edge, mu, width, cf_radius=cf_radius, deadline=deadline)
                running += 1
            if not running:  # past the deadline: the rest are not begun
                break
            edge, region = pool.next_done()
            running -= 1
            if isinstance(region, DeadlineExceeded):
                continue
            if isinstance(region, BaseException):
                raise region
            _keep(cache, _key(slider, edge, mu, width, cf_radius), region)
            out[edge] = region
    for edge in edges:
        if edge not in out and (twin := _twin(slider, edge)) in out:
            out[edge] = replace(out[twin], stable=stable_region(slider, edge, mu, width))
            cache.put(_key(slider, edge, mu, width, cf_radius), out[edge])
    return {edge: out[edge] for edge in edges if edge in out}


class _Workers:
    """Calls run in up to ``n`` worker processes forked now, or, with ``context`` None, at once in
    this process. Results come back in the order they finish (:meth:`next_done`). Leaving the
    ``with`` block normally waits for the workers to end; leaving it by an exception (Ctrl-C,
    SIGTERM, an error) kills them at once, and they die with this process if it is killed."""

    def __init__(self, n: int, context):
        self._done: queue.SimpleQueue = queue.SimpleQueue()
        with signals_blocked():  # the workers set their own handlers first (_worker_start)
            self._pool = None if context is None else context.Pool(n, initializer=_worker_start,
                                                                   initargs=(os.getpid(),))

    def submit(self, key, fn: Callable, /, *args, **kwargs) -> None:
        """Begin ``fn(*args, **kwargs)``; :meth:`next_done` gives ``(key, result)``, the result
        being the exception it raised, if it did."""
        if self._pool is None:
            try:
                self._done.put((key, fn(*args, **kwargs)))
            except Exception as err:
                self._done.put((key, err))
            return
        self._pool.apply_async(fn, args, kwargs, callback=lambda r: self._done.put((key, r)),
                               error_callback=lambda err: self._done.put((key, err)))

    def next_done(self) -> tuple:
        return self._done.get()

    def __enter__(self) -> "_Workers":
        return self

    def __exit__(self, kind, error, trace) -> None:
        if self._pool is None:
            return
        if kind is None:
            self._pool.close()
        else:
            self._pool.terminate()
        self._pool.join()


def _worker_start(parent: int) -> None:
    # Ctrl-C reaches every process of the terminal's group: the parent alone handles it (and
    # kills the workers, by SIGTERM), instead of each worker printing a traceback. A worker writes
    # nothing, so SIGKILL is the right end for it when the parent dies.
    die_with_parent(parent, signal.SIGKILL)
    quiet_child()


def _workers(n: int) -> _Workers:
    """``n`` forked workers, or this process for one, or where forking is not safe now
    (:func:`planner.model.processes.fork_context`)."""
    return _Workers(n, fork_context() if n > 1 else None)
