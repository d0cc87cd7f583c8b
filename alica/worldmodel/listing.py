"""Listings of a replica's state for traces and dumps, in a process-independent order."""

from __future__ import annotations

from alica.lang.fact import Fact
from alica.worldmodel.delta import Add
from alica.worldmodel.encoding import order_key
from alica.worldmodel.encoding import to_json as json_data
from alica.worldmodel.state import ReplicaState


def facts(state: ReplicaState) -> list[Fact]:
    """True facts and set memberships (``Fact(set_name, (item,))``), sorted.

    Args:
        state: the replica's state.

    Returns:
        The facts, sorted by :func:`~alica.worldmodel.encoding.order_key` of their flat
        ``(name, *args)`` form.
    """
    found = [Fact(name, args) for (name, args), value in state.live.items() if value is True]
    for name, table in state.sets.items():
        found.extend(Fact(name, (item,)) for item in table)
    return sorted(found, key=lambda fact: order_key(fact.flat))


def values(state: ReplicaState) -> list[tuple[str, tuple[object, ...], object]]:
    """Live function values that are not truth values, as ``(name, args, value)``.

    Args:
        state: the replica's state.

    Returns:
        The values, sorted by name, then arguments.
    """
    found = [(name, args, value) for (name, args), value in state.live.items() if type(value) is not bool]
    return sorted(found, key=lambda row: (row[0], order_key(row[1])))


def to_json(state: ReplicaState) -> dict[str, list[dict[str, object]]]:
    """The replicated state as JSON data: registers (tombstones too), sets and objects.

    Args:
        state: the replica's state.

    Returns:
        ``{"registers": [...], "sets": [...], "objects": [...]}``, each list
        sorted by name, then arguments or item; every row carries its stamp
        as ``[counter, writer]``.
    """
    writes = sorted(state.registers.values(), key=lambda write: (write.name, order_key(write.args)))
    registers: list[dict[str, object]] = [
        {
            "name": write.name,
            "args": json_data(write.args),
            "value": json_data(write.value),
            "stamp": [write.stamp.counter, write.stamp.writer],
            "expires": write.expires,
        }
        for write in writes
    ]
    return {
        "registers": registers,
        "sets": _adds(state.sets, "name", "item"),
        "objects": _adds(state.objects, "type", "object"),
    }


def _adds(tables: dict[str, dict[object, Add]], name_field: str, item_field: str) -> list[dict[str, object]]:
    rows = sorted(
        (add for table in tables.values() for add in table.values()),
        key=lambda add: (add.name, order_key(add.item)),
    )
    return [
        {name_field: add.name, item_field: json_data(add.item), "stamp": [add.stamp.counter, add.stamp.writer]}
        for add in rows
    ]
