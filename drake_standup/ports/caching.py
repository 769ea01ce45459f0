"""Drake cache entries for Python systems: compute a value once per change of
what it depends on, however many outputs (and integrator stages) read it."""

from __future__ import annotations

from collections.abc import Callable

from pydrake.common.value import Value
from pydrake.systems.framework import CacheEntry, Context, LeafSystem, ValueProducer


def declare_cached(
    system: LeafSystem,
    description: str,
    calc: Callable[[Context], object],
    prerequisites: set,
) -> CacheEntry:
    """A cache entry holding calc(context); read it with entry.Eval(context).

    prerequisites: the DependencyTickets calc reads (input ports, state, time);
    Drake recomputes the value only after one of them changed.
    """

    def _calc(context: Context, value) -> None:
        value.set_value(calc(context))

    return system.DeclareCacheEntry(
        description, ValueProducer(allocate=Value[object](None).Clone, calc=_calc), prerequisites
    )
