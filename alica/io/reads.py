"""How a formula reads the variables of its plan, for the checks of :mod:`alica.io.validate`.

A plan variable ``x`` read as a bare name is a static variable (one value for
the team); read as ``x(a)``, with one argument, it is a per-agent variable (one
value for each agent). The binder domain ``agents(E)`` names an entry point,
task or state ``E`` of the plan. These functions find both in a parsed formula.
"""

from __future__ import annotations

import re
from dataclasses import dataclass

from alica.lang.ast import Call, Name, Node, Quantified, agents_of, children


@dataclass(frozen=True, slots=True)
class Read:
    """A name read by a formula outside any quantifier that binds it.

    Args:
        name: the name read.
        per_agent: read with one argument, ``x(a)``; otherwise read bare, ``x``.
        column: 1-based column of the read in the formula's text.
        of_agent: for a per-agent read, whether the argument is a variable bound
            by an ``agents(E)`` binder (``frontier(a)`` in ``forall a in agents(E)``).
    """

    name: str
    per_agent: bool
    column: int
    of_agent: bool = False


@dataclass(frozen=True, slots=True)
class AgentDomain:
    """A binder domain ``agents(E)``: the name ``E`` and the column where it is written."""

    name: str
    column: int


def reads(root: Node) -> list[Read]:
    """The free names a formula reads bare or with one argument, in pre-order.

    A name bound by a quantifier around it is not a read of a plan variable
    (``forall x in T: p(x)`` reads no variable ``x``).
    """
    out: list[Read] = []
    stack: list[tuple[Node, frozenset[str], frozenset[str]]] = [(root, frozenset(), frozenset())]
    while stack:
        node, bound, agents = stack.pop()
        if isinstance(node, Quantified):
            names = {var for var, _ in node.binders}
            of_agents = {var for var, domain in node.binders if agents_of(domain) is not None}
            stack.append((node.body, bound | names, (agents - names) | of_agents))
            continue
        if isinstance(node, Name) and node.name not in bound:
            out.append(Read(node.name, False, node.column))
        elif isinstance(node, Call) and len(node.args) == 1 and node.name not in bound:
            arg = node.args[0]
            out.append(Read(node.name, True, node.column, isinstance(arg, Name) and arg.name in agents))
        stack.extend((child, bound, agents) for child in reversed(children(node)))
    return out


def agent_domains(root: Node, text: str) -> list[AgentDomain]:
    """Every ``agents(E)`` binder domain of a formula, located in ``text`` where it can be found."""
    out: list[AgentDomain] = []
    stack = [root]
    while stack:
        node = stack.pop()
        if isinstance(node, Quantified):
            start = max(node.column - 1, 0)
            for domain in dict.fromkeys(domain for _, domain in node.binders):  # a, b in agents(E): once
                name = agents_of(domain)
                if name is None:
                    continue
                found = re.compile(r"agents\s*\(\s*(" + re.escape(name) + r")\s*\)").search(text, start)
                column = found.start(1) + 1 if found is not None else node.column
                if found is not None:
                    start = found.end()
                out.append(AgentDomain(name, column))
        stack.extend(reversed(children(node)))
    return out
