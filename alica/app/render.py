"""Show a plan tree to a person: as indented text or as Graphviz dot.

Each node says what it is: plans with their entry points (task and
cardinality), states with their children and transitions, behaviours with
their skill and parameters, plan types with their alternatives, planning
problems with their elements and fallbacks.
"""

from __future__ import annotations

import shutil
import subprocess

from alica.errors import AlicaError
from alica.model import (
    AbstractPlan,
    Behaviour,
    Plan,
    PlanLibrary,
    PlanningProblem,
    PlanType,
    format_cardinality,
)


def text_tree(library: PlanLibrary, root: str) -> str:
    """The plan tree below ``root`` as indented text."""
    lines: list[str] = []
    _text(library, library.abstract(root), "", lines, set())
    return "\n".join(lines)


def _params(b: Behaviour) -> str:
    if not b.params:
        return ""
    return "(" + ", ".join(f"{p.name}={_value(p.value)}" for p in b.params) + ")"


def _value(value: object) -> str:
    if isinstance(value, tuple):
        return "[" + ", ".join(_value(v) for v in value) + "]"
    return str(value)


def _text(library: PlanLibrary, element: AbstractPlan, indent: str, lines: list[str], shown: set[str]) -> None:
    shown.add(element.name)
    if isinstance(element, Behaviour):
        lines.append(f"{indent}behaviour {element.name}: skill {element.skill}{_params(element)}")
        return
    if isinstance(element, PlanType):
        lines.append(f"{indent}plan type {element.name}: one of {', '.join(element.plans)}")
        for name in element.plans:
            _child(library, name, indent + "  ", lines, shown)
        return
    if isinstance(element, PlanningProblem):
        lines.append(
            f"{indent}planning problem {element.name}: planner {element.planner}, update every {element.update_time:g} s"
        )
        lines.append(f"{indent}  goal: {element.goal.text}")
        lines.append(f"{indent}  elements: {', '.join(element.elements)}")
        lines.append(
            f"{indent}  wait plan: {element.wait_plan or '-'}; alternative plan: {element.alternative_plan or '-'}"
        )
        return
    plan = element
    header = f"{indent}plan {plan.name}"
    if plan.description:
        header += f": {plan.description}"
    lines.append(header)
    if plan.signature is not None:
        params = " ".join(f"{v.name} - {v.type}" for v in plan.signature.parameters)
        lines.append(f"{indent}  as action ({params})")
    for ep in plan.entry_points:
        flag = ", success required" if ep.success_required else ""
        lines.append(f"{indent}  task {ep.task} [{ep.min}..{format_cardinality(ep.max)}{flag}] -> {ep.state}")
    for state in plan.states:
        kind = "" if state.kind.value == "normal" else f" ({state.kind.value})"
        lines.append(f"{indent}  state {state.name}{kind}")
        for child in state.children:
            _child(library, child.name, indent + "    ", lines, shown)
        for t in plan.out_transitions(state.name):
            cond = t.condition.text if t.condition else "always"
            sync = f" [sync {t.synchronisation}]" if t.synchronisation else ""
            lines.append(f"{indent}    -> {t.target} when {cond}{sync}")


def _child(library: PlanLibrary, name: str, indent: str, lines: list[str], shown: set[str]) -> None:
    element = library.abstract(name)
    if name in shown and not isinstance(element, Behaviour):
        kind = {Plan: "plan", PlanType: "plan type", PlanningProblem: "planning problem"}[type(element)]
        lines.append(f"{indent}{kind} {name} (shown above)")
        return
    _text(library, element, indent, lines, shown)


def dot_graph(library: PlanLibrary, root: str) -> str:
    """The plan tree below ``root`` as a Graphviz digraph: one cluster per plan.

    An edge to a plan ends at the border of the plan's cluster: it points at
    the plan's first entry point with ``lhead`` naming the cluster (the graph
    is ``compound``).
    """
    out = ["digraph alica {", "  compound=true; rankdir=LR; node [fontname=Helvetica fontsize=10];"]
    done: set[str] = set()
    _dot(library, library.abstract(root), out, done)
    out.append("}")
    return "\n".join(out) + "\n"


def _q(text: str) -> str:
    """A dot string; a line break in ``text`` becomes dot's centred line break ``\\n``."""
    return '"' + text.replace("\\", "\\\\").replace('"', '\\"').replace("\n", "\\n") + '"'


def _dot(library: PlanLibrary, element: AbstractPlan, out: list[str], done: set[str]) -> None:
    if element.name in done:
        return
    done.add(element.name)
    if isinstance(element, Behaviour):
        out.append(
            f"  {_q('b:' + element.name)} [shape=box style=rounded label={_q(element.name + chr(10) + 'skill ' + element.skill)}];"
        )
        return
    if isinstance(element, PlanType):
        out.append(f"  {_q('t:' + element.name)} [shape=folder label={_q('plan type ' + element.name)}];")
        for name in element.plans:
            _dot(library, library.abstract(name), out, done)
            out.append(_edge(library, "t:" + element.name, name, "style=dashed"))
        return
    if isinstance(element, PlanningProblem):
        label = f"problem {element.name}\ngoal: {element.goal.text}"
        out.append(f"  {_q('o:' + element.name)} [shape=hexagon label={_q(label)}];")
        for name, style in [
            *((n, "dotted") for n in element.elements),
            *((n, "dashed") for n in (element.wait_plan, element.alternative_plan) if n),
        ]:
            _dot(library, library.abstract(name), out, done)
            out.append(_edge(library, "o:" + element.name, name, f"style={style}"))
        return
    plan: Plan = element
    out.append(f"  subgraph {_q('cluster_' + plan.name)} {{ label={_q('plan ' + plan.name)}; style=rounded;")
    for ep in plan.entry_points:
        ep_id = f"e:{plan.name}:{ep.name}"
        out.append(f"    {_q(ep_id)} [shape=cds label={_q(f'{ep.task} [{ep.min}..{format_cardinality(ep.max)}]')}];")
        if ep.state:
            out.append(f"    {_q(ep_id)} -> {_q(f's:{plan.name}:{ep.state}')};")
    for state in plan.states:
        shape = {"success": "doublecircle", "failure": "Mcircle"}.get(state.kind.value, "circle")
        out.append(f"    {_q(f's:{plan.name}:{state.name}')} [shape={shape} label={_q(state.name)}];")
    for t in plan.transitions:
        label = t.condition.text if t.condition else ""
        out.append(
            f"    {_q(f's:{plan.name}:{t.source}')} -> {_q(f's:{plan.name}:{t.target}')} [label={_q(label)} fontsize=8];"
        )
    out.append("  }")
    for state in plan.states:
        for child in state.children:
            target = library.abstract(child.name)
            _dot(library, target, out, done)
            out.append(_edge(library, f"s:{plan.name}:{state.name}", child.name, "style=dashed arrowhead=open"))


def _edge(library: PlanLibrary, source: str, name: str, attributes: str) -> str:
    """An edge from node ``source`` to element ``name``; to a plan, it ends at the plan's cluster."""
    element = library.abstract(name)
    if isinstance(element, Plan):
        head = f"e:{name}:{element.entry_points[0].name}" if element.entry_points else f"p:{name}"
        attributes += f" lhead={_q('cluster_' + name)}"
    else:
        head = {Behaviour: "b:", PlanType: "t:", PlanningProblem: "o:"}[type(element)] + name
    return f"  {_q(source)} -> {_q(head)} [{attributes}];"


def svg(dot_text: str) -> str:
    """Render dot text to SVG with Graphviz.

    Raises:
        AlicaError: Graphviz's ``dot`` is not installed or failed.
    """
    exe = shutil.which("dot")
    if exe is None:
        raise AlicaError(
            "Graphviz is not installed ('dot' not found on PATH): install it (e.g. 'apt-get install graphviz') or use --format dot"
        )
    done = subprocess.run([exe, "-Tsvg"], input=dot_text, capture_output=True, text=True, check=False)
    if done.returncode != 0:
        raise AlicaError(f"Graphviz failed: {done.stderr.strip()}")
    return done.stdout
