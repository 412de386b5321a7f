"""What a session remembers, bounded: items filed under keys; past the bound, the oldest item of
the key filed under least recently is dropped first.

A :class:`~planner.queries.session.Planner` keeps its latest plans per goal (to join re-plans to),
the goals its reachability queries reached per start, and, for a scene of several parts, the
sessions of its moves. Each is a :class:`Memory`: at most ``limit`` items in all, across keys.

>>> memory = Memory(3)
>>> for goal, plan in [("g", 1), ("g", 2), ("h", 3), ("g", 4)]:
...     memory.file(goal, plan, plan)
>>> memory.items("g"), memory.items("h"), len(memory)   # h, filed under least recently, made room for 4
([4, 2, 1], [], 3)
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Hashable, Mapping
from types import MappingProxyType
from typing import Any

__all__ = ["Memory"]


class Memory:
    """At most ``limit`` items in all, each filed under a key and an item key (module docstring)."""

    def __init__(self, limit: int):
        self.limit = limit
        self._filed: OrderedDict[Hashable, OrderedDict[Hashable, Any]] = OrderedDict()
        self._count = 0

    def __len__(self) -> int:
        return self._count

    def file(self, key: Hashable, item_key: Hashable, item: Any) -> None:
        """File ``item`` under ``key`` as ``item_key`` (replacing one filed so before), the newest
        of both; then drop the oldest items until at most :attr:`limit` are left."""
        items = self._filed.setdefault(key, OrderedDict())
        self._count += item_key not in items
        items[item_key] = item
        items.move_to_end(item_key)
        self._filed.move_to_end(key)
        while self._count > self.limit:
            oldest_key, oldest = next(iter(self._filed.items()))
            oldest.popitem(last=False)
            self._count -= 1
            if not oldest:
                del self._filed[oldest_key]

    def get(self, key: Hashable, item_key: Hashable) -> Any | None:
        """The item filed under ``key`` as ``item_key``, or None."""
        return self._filed.get(key, {}).get(item_key)

    def items(self, key: Hashable) -> list[Any]:
        """The items filed under ``key``, the newest first."""
        return list(reversed(self._filed.get(key, {}).values()))

    def filed(self, key: Hashable) -> Mapping[Hashable, Any]:
        """The items filed under ``key`` by item key (read only)."""
        return MappingProxyType(self._filed.get(key, {}))
