"""The mapped files as YAML text: our dumper's data, made explicit, under a header.

The body is :func:`alica.io.dump.document_data` written by
:func:`alica.io.yaml_format.write_yaml`, the same as ``alica convert``
writes. Two things are made explicit because they carry the designer's
values: every entry point's ``min``, ``max`` (``"*"`` for the designer's
2147483647) and ``success_required``, every plan's utility threshold and
every synchronisation's timeouts.
The header names the designer file and lists the notes about it.
"""

from __future__ import annotations

import dataclasses
import textwrap
from collections.abc import Sequence

from alica.io.dump import document_data
from alica.io.yaml_format import write_yaml
from alica.model import Document, Plan

_ENTRY_KEYS = ("name", "task", "state", "min", "max", "success_required")
_PLAN_KEYS = (
    "name",
    "description",
    "variables",
    "pre",
    "run",
    "frequency",
    "utility",
    "constraints",
    "signature",
    "entry_points",
    "states",
    "synchronisations",
)


def _ordered(data: dict[str, object], keys: Sequence[str]) -> dict[str, object]:
    """``data`` with ``keys`` first in that order, the rest after."""
    out = {k: data[k] for k in keys if k in data}
    out.update((k, v) for k, v in data.items() if k not in out)
    return out


def _number(value: float) -> int | float:
    return int(value) if float(value).is_integer() else value


def _explicit_plan(plan: dict[str, object], model: Plan) -> dict[str, object]:
    entries = plan.get("entry_points")
    if isinstance(entries, list):
        fixed: list[object] = []
        for entry in entries:
            if isinstance(entry, dict):
                entry.setdefault("min", 0)
                entry.setdefault("max", "*")
                entry.setdefault("success_required", False)
                fixed.append(_ordered(entry, _ENTRY_KEYS))
            else:
                fixed.append(entry)
        plan["entry_points"] = fixed
    utility = plan.get("utility")
    if not isinstance(utility, dict):
        plan["utility"] = {"threshold": _number(model.utility.threshold)}
    syncs = plan.get("synchronisations")
    if isinstance(syncs, list):
        for data, sync in zip(syncs, model.synchronisations, strict=True):
            if isinstance(data, dict):
                data.setdefault("talk_timeout", _number(sync.talk_timeout))
                data.setdefault("sync_timeout", _number(sync.sync_timeout))
                data.setdefault("fail_on_timeout", sync.fail_on_timeout)
    return _ordered(plan, _PLAN_KEYS)


def header(origin: str, what: str, notes: Sequence[str]) -> str:
    """The comment at the top of an output file: where it came from (``origin``), what it holds, the notes about it."""
    lines = [f"Imported by 'alica import-designer' from {origin}"]
    lines += textwrap.wrap(f"({what}). A new import overwrites this file.", width=96)
    if notes:
        lines += ["", "Notes on this file:"]
        for note in notes:
            lines += textwrap.wrap(note, width=96, initial_indent="  - ", subsequent_indent="    ")
    return "".join(f"# {line}".rstrip() + "\n" for line in lines) + "\n"


def document_text(document: Document, imports: Sequence[str], head: str) -> str:
    """One output file: ``head``, then the document (with ``imports``) as YAML."""
    data = document_data(dataclasses.replace(document, imports=tuple(imports)))
    plans = data.get("plans")
    if isinstance(plans, list):
        data["plans"] = [
            _explicit_plan(p, plan) if isinstance(p, dict) else p for p, plan in zip(plans, document.plans, strict=True)
        ]
    return head + write_yaml({"alica": 1, **data})


def skills_text(skills: list[dict[str, object]], head: str) -> str:
    """The generated skill catalogue."""
    return head + write_yaml({"alica": 1, "skills": skills})
