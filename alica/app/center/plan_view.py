"""The plan tree of a plan file as data and as an SVG drawing, for the plan-file view.

Each plan is a box: its entry points (task and cardinality), its states as
circles in a row (success and failure states marked), its transitions as
labelled arcs, and below each state the boxes of the state's children. A plan,
plan type or problem seen earlier in the tree is drawn once and referred to
after that.
"""

from __future__ import annotations

from html import escape
from typing import Any

from alica.model import Behaviour, Plan, PlanLibrary, PlanningProblem, PlanType, format_cardinality


def plan_tree(library: PlanLibrary, root: str) -> dict[str, Any]:
    """The tree below ``root`` as JSON-ready data."""
    return _node(library, root, set())


def _node(library: PlanLibrary, name: str, shown: set[str]) -> dict[str, Any]:
    element = library.abstract(name)
    if isinstance(element, Behaviour):
        return {"kind": "behaviour", "name": name, "skill": element.skill}
    if name in shown:
        return {"kind": "ref", "name": name}
    shown.add(name)
    if isinstance(element, PlanType):
        return {"kind": "plantype", "name": name, "children": [_node(library, p, shown) for p in element.plans]}
    if isinstance(element, PlanningProblem):
        others = [*element.elements, *(n for n in (element.wait_plan, element.alternative_plan) if n)]
        return {
            "kind": "problem",
            "name": name,
            "goal": element.goal.text,
            "children": [_node(library, p, shown) for p in dict.fromkeys(others)],
        }
    plan: Plan = element
    return {
        "kind": "plan",
        "name": name,
        "entry_points": [
            {"task": ep.task, "min": ep.min, "max": format_cardinality(ep.max), "state": ep.state}
            for ep in plan.entry_points
        ],
        "states": [
            {
                "name": s.name,
                "kind": s.kind.value,
                "children": [_node(library, c.name, shown) for c in s.children],
            }
            for s in plan.states
        ],
        "transitions": [
            {"source": t.source, "target": t.target, "condition": t.condition.text if t.condition else ""}
            for t in plan.transitions
        ],
    }


# -- drawing ---------------------------------------------------------------

PAD, GAP, R, HEAD = 12.0, 16.0, 22.0, 22.0
STATE_W = 120.0


def plan_svg(library: PlanLibrary, root: str) -> str:
    """The tree below ``root`` as a standalone SVG document."""
    tree = plan_tree(library, root)
    width, height, body = _layout(tree)
    return (
        f'<svg xmlns="http://www.w3.org/2000/svg" class="plan-tree" width="{width + 2 * PAD:.0f}" '
        f'height="{height + 2 * PAD:.0f}" font-family="sans-serif" font-size="11">'
        '<defs><marker id="arrow" viewBox="0 0 10 10" refX="10" refY="5" markerWidth="6" markerHeight="6" '
        'orient="auto-start-reverse"><path d="M0,0 L10,5 L0,10 z" fill="#555"/></marker></defs>'
        f'<g transform="translate({PAD},{PAD})">{body}</g></svg>'
    )


def _text(x: float, y: float, text: str, cls: str = "", anchor: str = "start") -> str:
    return f'<text x="{x:.1f}" y="{y:.1f}" class="{cls}" text-anchor="{anchor}">{escape(text)}</text>'


def _layout(node: dict[str, Any]) -> tuple[float, float, str]:
    """Width, height and SVG body (at the origin) of a node's box."""
    kind = node["kind"]
    if kind in ("behaviour", "ref"):
        label = f"behaviour {node['name']}" if kind == "behaviour" else f"{node['name']} (drawn above)"
        sub = f"skill {node['skill']}" if kind == "behaviour" else ""
        w = max(120.0, 7.0 * max(len(label), len(sub)) + 16)
        body = (
            f'<g class="{kind}" data-name="{escape(node["name"])}"><rect width="{w:.0f}" height="38" rx="6" '
            f'fill="#eef6ee" stroke="#4a7"/>{_text(8, 15, label, "title")}{_text(8, 30, sub)}</g>'
        )
        return w, 38.0, body
    if kind in ("plantype", "problem"):
        title = ("plan type " if kind == "plantype" else "planning problem ") + node["name"]
        extra = [f"goal: {node['goal']}"] if kind == "problem" else []
        return _column(node, title, extra, "#f7f3e8", "#b94")
    # a plan
    eps = [f"task {e['task']} [{e['min']}..{e['max']}] -> {e['state']}" for e in node["entry_points"]]
    top = HEAD + 15 * len(eps) + 8
    parts: list[str] = []
    x = PAD
    centres: dict[str, tuple[float, float]] = {}
    row_y = top + 30 + R
    below = row_y + R + 28
    col_h = 0.0
    for state in node["states"]:
        kids = [_layout(c) for c in state["children"]]
        kw = max([k[0] for k in kids], default=0.0)
        cw = max(STATE_W, kw)
        cx = x + cw / 2
        centres[state["name"]] = (cx, row_y)
        fill = {"success": "#dfd", "failure": "#fdd"}.get(state["kind"], "#fff")
        ring = (
            f'<circle cx="{cx:.1f}" cy="{row_y:.1f}" r="{R - 4}" fill="none" stroke="#333"/>'
            if state["kind"] in ("success", "failure")
            else ""
        )
        parts.append(
            f'<g class="state" data-state="{escape(state["name"])}"><circle cx="{cx:.1f}" cy="{row_y:.1f}" r="{R}" '
            f'fill="{fill}" stroke="#333"/>{ring}{_text(cx, row_y + R + 13, state["name"], "state-name", "middle")}</g>'
        )
        y = below
        for kw_, kh, kb in kids:
            kx = x + (cw - kw_) / 2
            parts.append(
                f'<line x1="{cx:.1f}" y1="{row_y + R + 16:.1f}" x2="{kx + kw_ / 2:.1f}" y2="{y:.1f}" '
                'stroke="#888" stroke-dasharray="4 3"/>'
            )
            parts.append(f'<g transform="translate({kx:.1f},{y:.1f})">{kb}</g>')
            y += kh + GAP
        col_h = max(col_h, y - below)
        x += cw + GAP
    for i, t in enumerate(node["transitions"]):
        if t["source"] not in centres or t["target"] not in centres:
            continue
        (x1, y1), (x2, y2) = centres[t["source"]], centres[t["target"]]
        lift = 18 + 8 * (i % 3)
        sign = 1 if x2 >= x1 else -1
        sx, ex = x1 + sign * R * 0.7, x2 - sign * R * 0.7
        mid = (sx + ex) / 2
        parts.append(
            f'<path class="transition" d="M{sx:.1f},{y1 - R * 0.7:.1f} Q{mid:.1f},{y1 - R - lift:.1f} '
            f'{ex:.1f},{y2 - R * 0.7:.1f}" fill="none" stroke="#555" marker-end="url(#arrow)"/>'
        )
        cond = t["condition"] if len(t["condition"]) <= 40 else t["condition"][:39] + "\u2026"
        parts.append(_text(mid, y1 - R - lift / 2 - 2, cond, "condition", "middle"))
    w = max(x - GAP + PAD, 7.0 * max([len(node["name"]) + 5, *(len(e) for e in eps)]) + 2 * PAD)
    h = below + col_h + PAD
    head = [_text(PAD, 16, f"plan {node['name']}", "title")]
    head += [_text(PAD, HEAD + 12 + 15 * i, e, "entry") for i, e in enumerate(eps)]
    body = (
        f'<g class="plan" data-name="{escape(node["name"])}"><rect width="{w:.0f}" height="{h:.0f}" rx="10" '
        f'fill="#f4f7fc" stroke="#46a"/>{"".join(head)}{"".join(parts)}</g>'
    )
    return w, h, body


def _column(node: dict[str, Any], title: str, extra: list[str], fill: str, stroke: str) -> tuple[float, float, str]:
    kids = [_layout(c) for c in node["children"]]
    top = HEAD + 15 * len(extra) + 8
    parts = [_text(PAD, 16, title, "title")] + [_text(PAD, HEAD + 12 + 15 * i, e) for i, e in enumerate(extra)]
    x = PAD
    for kw, _kh, kb in kids:
        parts.append(f'<g transform="translate({x:.1f},{top:.1f})">{kb}</g>')
        x += kw + GAP
    w = max(x - GAP + PAD, 7.0 * max([len(title), *(len(e) for e in extra)]) + 2 * PAD)
    h = top + max([k[1] for k in kids], default=0.0) + PAD
    kind = node["kind"]
    body = (
        f'<g class="{kind}" data-name="{escape(node["name"])}"><rect width="{w:.0f}" height="{h:.0f}" rx="10" '
        f'fill="{fill}" stroke="{stroke}"/>{"".join(parts)}</g>'
    )
    return w, h, body
