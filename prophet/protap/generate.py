"""Problem generation (ProTaP Algorithm 2): a :class:`ProblemSpec` from arguments or facts, written as RDDL.

Three ways to a spec: :func:`random_spec` (the paper's demonstration mode,
seeded), :func:`spec_from_facts` (robot positions and goals as plain data, as
a team's world model has them) and :func:`appendix_c_spec` (the paper's sample
problem with its typos fixed). :func:`instance_text` writes the instance and
:func:`write_problem` writes it next to the domain.

>>> spec = random_spec(robots=2, width=5, height=5, goals=3, seed=0)
>>> "max-nondef-actions = 4;" in instance_text(spec)
True
"""

from __future__ import annotations

import random
from collections.abc import Iterable, Mapping, Sequence
from importlib import resources
from pathlib import Path

from alica.prophet.protap.spec import (
    DOMAIN_NAME,
    MANIPULATION,
    USER_DEFINED,
    Action,
    Cell,
    Goal,
    ProblemSpec,
    Robot,
    rddl_name,
)


def domain_text() -> str:
    """The RDDL text of the domain ``multi_ros_robot_mdp`` (the package's ``domain.rddl``)."""
    return resources.files("alica.prophet.protap").joinpath("domain.rddl").read_text(encoding="utf-8")


def _actions(manipulation: int, uda: int) -> tuple[Action, ...]:
    kinds = [MANIPULATION] * manipulation + [USER_DEFINED] * uda
    return tuple(Action(f"a{i + 1}", kind) for i, kind in enumerate(kinds))


def random_spec(
    robots: int = 2,
    width: int = 5,
    height: int = 5,
    goals: int = 3,
    seed: int = 0,
    *,
    manipulation_actions: int = 2,
    user_actions: int = 1,
    prob_goto: float = 0.9,
    utility: float = 100.0,
    horizon: int = 10,
    discount: float = 1.0,
) -> ProblemSpec:
    """A random problem as in the paper's demonstration (Algorithm 1, lines 6, 11 and 16).

    Robots start at random cells (several may share one); goals lie at
    distinct random cells, each with a random action. The same arguments give
    the same spec.

    Args:
        robots: the number of robots ``r1..``.
        width: the number of columns.
        height: the number of rows.
        goals: the number of goals ``g1..`` (1 to ``width * height``).
        seed: the seed of the ``random.Random`` that places everything.
        manipulation_actions: the number of manipulation actions (the paper: 2).
        user_actions: the number of user-defined actions after them (the paper: 1).
        prob_goto: every robot's goto success probability.
        utility: every goal's utility.
        horizon: the number of steps.
        discount: the discount factor.

    Returns:
        The spec, its concurrency bound 2 x the number of robots.

    Raises:
        ValueError: for more goals than cells or an invalid spec.
    """
    if goals > width * height:
        raise ValueError(f"{goals} goals do not fit on distinct cells of a {width}x{height} grid")
    rng = random.Random(seed)
    actions = _actions(manipulation_actions, user_actions)
    starts = [(rng.randrange(width), rng.randrange(height)) for _ in range(robots)]
    places = rng.sample(range(width * height), goals)
    return ProblemSpec(
        robots=tuple(Robot(f"r{i + 1}", cell, prob_goto) for i, cell in enumerate(starts)),
        actions=actions,
        goals=tuple(
            Goal(f"g{i + 1}", actions[rng.randrange(len(actions))].name, (place % width, place // width), utility)
            for i, place in enumerate(places)
        ),
        width=width,
        height=height,
        horizon=horizon,
        discount=discount,
    )


def spec_from_facts(
    robots: Mapping[str, Cell] | Iterable[tuple[str, Cell]],
    goals: Iterable[Mapping[str, object]],
    width: int,
    height: int,
    *,
    user_actions: Sequence[str] = (),
    prob_goto: float | Mapping[str, float] = 0.9,
    horizon: int = 10,
    discount: float = 1.0,
    name: str = "multi_ros_robot_inst_mdp__1",
) -> ProblemSpec:
    """A problem from a world model's facts, given as plain data (Algorithm 1, lines 9 and 14).

    Names become valid RDDL names with :func:`~alica.prophet.protap.spec.rddl_name`
    (``"scout-1"`` -> ``scout_1``); objects keep the order they were given in,
    so a caller maps them back by position.

    Args:
        robots: robot name -> 0-based cell, or ``(name, cell)`` pairs.
        goals: one mapping per goal with ``"name"``, ``"action"``, ``"cell"``
            and optionally ``"utility"`` (default 100).
        width: the number of columns.
        height: the number of rows.
        user_actions: the action names that are user-defined actions (``uda``);
            the other goal actions are manipulation actions.
        prob_goto: the goto success probability, one for all or one per robot name.
        horizon: the number of steps.
        discount: the discount factor.
        name: the instance name.

    Returns:
        The spec; its actions are the goals' actions and then the other user actions.

    Raises:
        ValueError: for an invalid spec (a cell off the grid, two names that
            become one, ...).
    """
    pairs = list(robots.items()) if isinstance(robots, Mapping) else list(robots)
    goal_list = list(goals)
    action_names: list[str] = []
    for goal in goal_list:
        if str(goal["action"]) not in action_names:
            action_names.append(str(goal["action"]))
    action_names.extend(action for action in user_actions if action not in action_names)
    uda = set(user_actions)

    def probability(robot: str) -> float:
        return float(prob_goto[robot]) if isinstance(prob_goto, Mapping) else float(prob_goto)

    def cell(value: object) -> Cell:
        if not isinstance(value, Sequence) or len(value) != 2:
            raise ValueError(f"a cell is an (x, y) pair, not {value!r}")
        return (int(value[0]), int(value[1]))

    return ProblemSpec(
        robots=tuple(Robot(rddl_name(robot, "robot"), cell(at), probability(robot)) for robot, at in pairs),
        actions=tuple(
            Action(rddl_name(action, "act"), USER_DEFINED if action in uda else MANIPULATION) for action in action_names
        ),
        goals=tuple(
            Goal(
                rddl_name(str(goal["name"]), "goal"),
                rddl_name(str(goal["action"]), "act"),
                cell(goal["cell"]),
                float(goal.get("utility", 100.0)),  # type: ignore[arg-type]
            )
            for goal in goal_list
        ),
        width=width,
        height=height,
        horizon=horizon,
        discount=discount,
        name=name,
    )


def appendix_c_spec() -> ProblemSpec:
    """The paper's sample problem (Appendix C) with its typos fixed.

    The paper's ``init-state`` names robots ``r0`` and ``r1`` and a column
    ``x0`` that the objects block does not have (its generator counts robots
    and cells from 0 but names objects from 1). Read here as the robot objects
    ``r1``, ``r2`` and the column ``x1``: ``robotAt(r1, x4, y1)``,
    ``robotAt(r2, x1, y2)``. ``GOAL_UTILITY`` is given for every goal (the
    paper set it for ``g1`` and ``g2`` only; the default is the same 100),
    and ``GOTO_COST`` is indexed by cell objects, not ``xGoto1``.
    """
    return ProblemSpec(
        robots=(Robot("r1", (3, 0)), Robot("r2", (0, 1))),
        actions=_actions(2, 1),
        goals=(Goal("g1", "a2", (3, 1)), Goal("g2", "a1", (0, 0)), Goal("g3", "a2", (2, 3))),
        width=5,
        height=5,
    )


def _number(value: float) -> str:
    text = f"{value:.6f}".rstrip("0")
    return text + "0" if text.endswith(".") else text


def instance_text(spec: ProblemSpec) -> str:
    """The RDDL non-fluents block and instance of ``spec`` (Algorithm 2, lines 1-13).

    Args:
        spec: the problem.

    Returns:
        The text: objects, ``PROB_GOTO``, ``DO_COST``, ``GOTO_COST`` for every
        pair of cells, ``GOAL_UTILITY`` and ``GOAL`` for every goal, the robots'
        start cells, ``max-nondef-actions``, horizon and discount.
    """
    xs, ys = spec.x_names, spec.y_names
    cells = [(x, y) for x in range(spec.width) for y in range(spec.height)]

    def at(cell: Cell) -> str:
        return f"{xs[cell[0]]}, {ys[cell[1]]}"

    def objects(kind: str, names: Iterable[str]) -> str:
        return f"        {kind} : {{{', '.join(names)}}};"

    lines = [
        "// Generated by alica.prophet.protap (ProTaP Algorithm 2).",
        f"non-fluents nf_{spec.name} {{",
        f"    domain = {DOMAIN_NAME};",
        "    objects {",
        objects("robot", (robot.name for robot in spec.robots)),
        objects("action", (action.name for action in spec.actions)),
        objects("xPos", xs),
        objects("yPos", ys),
        objects("goal", (goal.name for goal in spec.goals)),
        "    };",
        "    non-fluents {",
    ]
    lines += [f"        PROB_GOTO({robot.name}) = {_number(robot.prob_goto)};" for robot in spec.robots]
    lines += [
        f"        DO_COST({robot.name}, {action.name}) = {_number(spec.do_costs[r][a])};"
        for r, robot in enumerate(spec.robots)
        for a, action in enumerate(spec.actions)
    ]
    lines += [
        f"        GOTO_COST({at(start)}, {at(target)}) = {_number(spec.goto_cost(start, target))};"
        for start in cells
        for target in cells
    ]
    lines += [f"        GOAL_UTILITY({goal.name}) = {_number(goal.utility)};" for goal in spec.goals]
    lines += [f"        GOAL({goal.name}, {goal.action}, {at(goal.cell)}) = true;" for goal in spec.goals]
    lines += [
        "    };",
        "}",
        "",
        f"instance {spec.name} {{",
        f"    domain = {DOMAIN_NAME};",
        f"    non-fluents = nf_{spec.name};",
        "    init-state {",
        *(f"        robotAt({robot.name}, {at(robot.cell)}) = true;" for robot in spec.robots),
        "    };",
        f"    max-nondef-actions = {spec.max_nondef_actions};",
        f"    horizon = {spec.horizon};",
        f"    discount = {_number(spec.discount)};",
        "}",
        "",
    ]
    return "\n".join(lines)


def write_problem(spec: ProblemSpec, out_dir: str | Path) -> tuple[Path, Path]:
    """Write ``domain.rddl`` and ``instance.rddl`` for ``spec`` into ``out_dir`` (created if missing).

    Returns:
        The paths of the domain and the instance file.
    """
    folder = Path(out_dir)
    folder.mkdir(parents=True, exist_ok=True)
    domain, instance = folder / "domain.rddl", folder / "instance.rddl"
    domain.write_text(domain_text(), encoding="utf-8")
    instance.write_text(instance_text(spec), encoding="utf-8")
    return domain, instance
