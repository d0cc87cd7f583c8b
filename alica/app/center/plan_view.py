"""The plan tree of a plan file as data and as an SVG drawing, for the plan-file view.

Each plan is a box: its entry points (task and cardinality), its states as
circles in a row (success and failure states marked), its transitions as
labelled arcs, and below each state the boxes of the state's children. A plan,
plan type or problem seen earlier in the tree is drawn once and referred to
after that.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable
from html import escape
from pathlib import Path
from typing import Any

from alica.errors import AlicaError
from alica.io import Loader, plans_dir
from alica.model import Behaviour, Plan, PlanLibrary, PlanningProblem, PlanType, format_cardinality


def plan_tree(library: PlanLibrary, root: str, *, refs: bool = True) -> dict[str, Any]:
    """The tree below ``root`` as JSON-ready data.

    Args:
        refs: a plan, plan type or problem seen earlier in the tree is a ``ref`` node after
            that; without, each is spelled out wherever it is used (a ``ref`` only where it
            would contain itself), so that every plan node a team can be in has its place.
    """
    return _node(library, root, set(), refs)


def _node(library: PlanLibrary, name: str, shown: set[str], refs: bool) -> dict[str, Any]:
    element = library.abstract(name)
    if isinstance(element, Behaviour):
        return {"kind": "behaviour", "name": name, "skill": element.skill}
    if name in shown:
        return {"kind": "ref", "name": name}
    if refs:
        shown.add(name)  # one set for the whole tree: seen anywhere before
    else:
        shown = shown | {name}  # the plans on the way down: seen above this one
    if isinstance(element, PlanType):
        return {"kind": "plantype", "name": name, "children": [_node(library, p, shown, refs) for p in element.plans]}
    if isinstance(element, PlanningProblem):
        others = [*element.elements, *(n for n in (element.wait_plan, element.alternative_plan) if n)]
        return {
            "kind": "problem",
            "name": name,
            "goal": element.goal.text,
            "children": [_node(library, p, shown, refs) for p in dict.fromkeys(others)],
        }
    plan: Plan = element
    return {
        "kind": "plan",
        "name": name,
        "entry_points": [
            {"name": ep.name, "task": ep.task, "min": ep.min, "max": format_cardinality(ep.max), "state": ep.state}
            for ep in plan.entry_points
        ],
        "states": [
            {
                "name": s.name,
                "kind": s.kind.value,
                "children": [_node(library, c.name, shown, refs) for c in s.children],
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


# -- the plan trees of a trace's agents -------------------------------------

SHIPPED = "alica:plans/"
"""How a header names a plan file shipped with alica (under :func:`alica.io.plans_dir`)."""


def plan_candidates(given: str, trace_path: str | Path) -> list[Path]:
    """Where a header's plan file may be: a shipped one under the shipped plans; else as
    given (from where the run started), then relative to the trace's folder."""
    if given.startswith(SHIPPED):
        try:
            return [plans_dir() / given[len(SHIPPED) :]]
        except FileNotFoundError:
            return []
    path = Path(given)
    if path.is_absolute():
        return [path]
    return [path, Path(trace_path).parent / path]


def trace_plans(
    meta: dict[str, Any], trace_path: str | Path, make_loader: Callable[[], Loader] = Loader
) -> tuple[list[PlanLibrary], list[str]]:
    """The plan libraries of the plan files a trace's header names, and why any did not load.

    Args:
        make_loader: a new loader for each file (with the run's skills and plan folders,
            :func:`alica.app.trace_sources.viewer_sources`).
    """
    files = meta.get("plans")
    if not isinstance(files, list) or not files:
        return [], ["the trace's header names no plan files: no plan trees"]
    libraries: list[PlanLibrary] = []
    notes: list[str] = []
    for given in files:
        library, why = _load_library(str(given), trace_path, make_loader)
        if library is None:
            notes.append(why)
        else:
            libraries.append(library)
    return libraries, notes


def entry_states(libraries: Iterable[PlanLibrary]) -> dict[str, dict[str, str]]:
    """Plan -> entry point -> the state it starts in, for every plan of ``libraries``.

    An allocation event names an agent's entry point (``entries``: agent -> entry point name,
    which is the task's name unless the plan names it otherwise); a task's name stands for its
    entry point too where the plan has one entry point of that task.
    """
    out: dict[str, dict[str, str]] = {}
    for library in libraries:
        for name, plan in library.plans.items():
            if name in out:
                continue
            starts = {ep.name: ep.state for ep in plan.entry_points if ep.state is not None}
            tasks = [ep.task for ep in plan.entry_points]
            for ep in plan.entry_points:
                if ep.state is not None and tasks.count(ep.task) == 1:
                    starts.setdefault(ep.task, ep.state)
            out[name] = starts
    return out


def trace_trees(
    meta: dict[str, Any],
    trace_path: str | Path,
    make_loader: Callable[[], Loader] = Loader,
    *,
    loaded: tuple[list[PlanLibrary], list[str]] | None = None,
) -> dict[str, Any]:
    """Each agent's plan tree, from the plan files a trace's header names.

    Args:
        make_loader: a new loader for each file (see :func:`trace_plans`).
        loaded: what :func:`trace_plans` gave, when the caller has it already.

    Returns:
        ``{"trees": {ROOT: tree}, "agents": {AGENT: ROOT}, "notes": [...]}``: the trees
        (:func:`plan_tree` without refs) of the roots the agents run (the header's ``agents``
        ``plan``, else its ``root``), which agent runs which, and why a file or a root is
        missing (never an exception).
    """
    given_agents = meta.get("agents")
    agents: dict[str, Any] = given_agents if isinstance(given_agents, dict) else {}
    root = meta.get("root")
    wanted: dict[str, str] = {}
    for name, info in sorted(agents.items()):
        plan = info.get("plan") if isinstance(info, dict) else None
        plan = plan if isinstance(plan, str) else root
        if isinstance(plan, str):
            wanted[str(name)] = plan
    libraries, found_notes = loaded if loaded is not None else trace_plans(meta, trace_path, make_loader)
    notes = list(found_notes)
    if not isinstance(meta.get("plans"), list) or not meta.get("plans"):
        return {"trees": {}, "agents": {}, "notes": notes}
    trees: dict[str, dict[str, Any]] = {}
    shown: dict[str, str] = {}
    for name, plan in wanted.items():
        if plan not in trees:
            for library in libraries:
                try:
                    trees[plan] = plan_tree(library, plan, refs=False)
                    break
                except KeyError:
                    continue
            else:
                if libraries:
                    notes.append(f"no plan '{plan}' (agent {name}) in the trace's plan files")
                continue
        shown[name] = plan
    return {"trees": trees, "agents": shown, "notes": notes}


def plan_roots(trace_path: str | Path) -> list[Path]:
    """The folders a trace's header may name plan files in: the trace's folder, its project, the plan path.

    A header is data from a file, or from the network for a live team: the center reads no plan
    file outside these (so a header cannot make it tell whether another file exists, or show its
    first key). The project is the nearest folder above the trace's holding ``pyproject.toml``,
    ``.git``, ... (:func:`alica.io.plan_paths.project_root`); the plan path is the shipped plans and
    ``ALICA_PLAN_PATH``.
    """
    from alica.io.plan_paths import PlanPathError, default_search_path, project_root

    folder = Path(trace_path).parent.resolve()
    roots = [folder]
    project = project_root(folder / "trace")
    if project is not None:
        roots.append(project.resolve())
    try:
        roots += [path.resolve() for path in default_search_path()]
    except PlanPathError:
        pass
    return roots


def find_plan_file(given: str, trace_path: str | Path) -> tuple[Path | None, str]:
    """The file a header's plan file names, among those the center may read (:func:`plan_roots`), or why none."""
    roots = plan_roots(trace_path)
    candidates = [p for p in plan_candidates(given, trace_path) if any(p.resolve().is_relative_to(r) for r in roots)]
    if not candidates:
        return None, (
            f"plan file {given} is outside the trace's folder, its project and the plan path: not read (add its "
            "folder to ALICA_PLAN_PATH to show its plans)"
        )
    tried = [p for p in candidates if p.is_file()]
    if not tried:
        where = " or ".join(str(p) for p in candidates)
        return None, f"plan file {given} not found (looked for {where}): no plan tree from it"
    return tried[0], ""


def _load_library(
    given: str, trace_path: str | Path, make_loader: Callable[[], Loader] = Loader
) -> tuple[PlanLibrary | None, str]:
    path, why = find_plan_file(given, trace_path)
    if path is None:
        return None, why
    try:
        return make_loader().load(path), ""
    except (AlicaError, OSError, ValueError) as exc:
        first = str(exc).splitlines()[0] if str(exc) else type(exc).__name__
        return None, f"plan file {given} does not load: {first}"
