"""Reading RDDL: the ProTaP paper's domain and instance, every construct of the subset, precedence."""

from __future__ import annotations

from pathlib import Path

import pytest

from alica.prophet.rddl import (
    Aggregate,
    Apply,
    Assignment,
    Binary,
    BoolConst,
    Distribution,
    EnumValue,
    If,
    IntConst,
    Name,
    Neg,
    Not,
    Param,
    RealConst,
    TypedParam,
    parse_expr,
    parse_rddl,
    read_rddl,
)

DATA = Path(__file__).parent / "data"
DOMAIN = DATA / "multi_ros_robot_mdp.rddl"
INSTANCE = DATA / "multi_ros_robot_inst_mdp__1.rddl"


def p(name: str) -> Param:
    return Param(name)


def test_paper_domain_reads_with_its_declarations() -> None:
    domain = read_rddl(DOMAIN).domain
    assert domain is not None
    assert domain.name == "multi_ros_robot_mdp"
    assert domain.requirements == ("continuous", "constrained-state", "concurrent")
    assert [t.name for t in domain.types] == ["robot", "action", "xPos", "yPos", "goal"]
    assert all(t.parent == Name("object") for t in domain.types)
    kinds = {v.name: v.kind for v in domain.pvariables}
    assert kinds == {
        "PROB_GOTO": "non-fluent",
        "GOTO_COST": "non-fluent",
        "DO_COST": "non-fluent",
        "GOAL_UTILITY": "non-fluent",
        "GOAL": "non-fluent",
        "robotAt": "state-fluent",
        "done": "state-fluent",
        "goto": "action-fluent",
        "do": "action-fluent",
    }
    prob = domain.pvariables[0]
    assert prob.params == (Name("robot"),) and prob.range == Name("real") and prob.default == RealConst(0.9)
    assert domain.pvariables[3].default == IntConst(100)
    assert [(c.name, c.primed, [x.name for x in c.params]) for c in domain.cpfs] == [
        ("robotAt", True, ["?r", "?x", "?y"]),
        ("done", True, ["?g"]),
    ]
    assert len(domain.state_action_constraints) == 3
    assert domain.action_preconditions == () and domain.state_invariants == ()


def test_paper_domain_places_and_structure() -> None:
    domain = read_rddl(DOMAIN).domain
    assert domain is not None
    robot_at = domain.cpfs[0]
    assert (robot_at.line, robot_at.column) == (61, 5)
    assert isinstance(robot_at.expr, If)
    assert robot_at.expr.then == Distribution(
        "Bernoulli", (Binary("*", Apply("goto", (p("?r"), p("?x"), p("?y"))), Apply("PROB_GOTO", (p("?r"),))),)
    )
    assert isinstance(robot_at.expr.else_, If)
    assert robot_at.expr.else_.then == Distribution("KronDelta", (BoolConst(False),))
    # The sum reaches to the right, so DO_COST(?r, ?a) is inside the sum that binds ?r and ?a.
    reward = domain.reward
    assert isinstance(reward, Binary) and reward.op == "-"
    assert isinstance(reward.left, Binary)
    do_cost = reward.left.right
    assert isinstance(do_cost, Aggregate) and do_cost.op == "sum"
    assert do_cost.params == (TypedParam("?r", Name("robot")), TypedParam("?a", Name("action")))
    assert do_cost.body == Binary("*", Apply("do", (p("?r"), p("?a"))), Apply("DO_COST", (p("?r"), p("?a"))))
    # forall_{?r} [sum ...] <= 1: the forall holds the comparison.
    first = domain.state_action_constraints[0]
    assert isinstance(first, Aggregate) and first.op == "forall"
    assert isinstance(first.body, Binary) and first.body.op == "<=" and first.body.right == IntConst(1)


def test_paper_instance_reads_against_the_domain() -> None:
    domain = read_rddl(DOMAIN).domain
    blocks = read_rddl(INSTANCE, domain=domain)
    assert blocks.domain is None
    nf, instance = blocks.non_fluents, blocks.instance
    assert nf is not None and instance is not None
    assert nf.domain == Name("multi_ros_robot_mdp")
    assert [(o.type.text, [n.text for n in o.names]) for o in nf.objects] == [
        ("robot", ["r1", "r2"]),
        ("action", ["a1", "a2", "a3"]),
        ("xPos", [f"x{i}" for i in range(1, 6)]),
        ("yPos", [f"y{i}" for i in range(1, 6)]),
        ("goal", ["g1", "g2", "g3"]),
    ]
    assert sum(v.name == "GOTO_COST" for v in nf.values) == 625
    assert Assignment("GOTO_COST", tuple(map(Name, ("x1", "y1", "x2", "y2"))), RealConst(1.41)) in nf.values
    assert nf.values[-1] == Assignment("GOAL", tuple(map(Name, ("g3", "a2", "x3", "y4"))), BoolConst(True))
    assert instance.non_fluents == Name("nf_multi_ros_robot_inst_mdp__1")
    assert [a.args for a in instance.init_state] == [
        tuple(map(Name, ("r1", "x4", "y1"))),
        tuple(map(Name, ("r2", "x1", "y2"))),
    ]
    assert (instance.max_nondef_actions, instance.horizon, instance.discount) == (4, 10, 1.0)


FULL = """
// every construct of the subset
domain full {
    requirements = {reward-deterministic, intermediate-nodes};
    types {
        cell : object;
        room : cell;
        grade : {@low, @mid, @high};
    };
    pvariables {
        SIZE : {non-fluent, int, default = -3};
        WEIGHT(cell) : {non-fluent, real, default = -0.5};
        ADJ(cell, cell) : {non-fluent, bool, default = false};
        mode : {state-fluent, grade, default = @low};
        lit(cell) : {state-fluent, bool, default = true};
        count : {state-fluent, int, default = 0};
        heat(room) : {interm-fluent, real, level = 1};
        seen(cell) : {observ-fluent, bool};
        flip(cell) : {action-fluent, bool, default = false};
    };
    cpfs {
        heat(?r) = Normal(WEIGHT(?r), 1.5) + DiracDelta(2);
        seen(?c) = Bernoulli(0.8) & lit'(?c);
        lit'(?c) = if (flip(?c) <=> lit(?c)) then false else exists_{?d : cell} [ADJ(?c, ?d) => lit(?d)];
        count' = prod_{?c : cell} [if (lit(?c)) then 2 else 1] * -SIZE;
        mode' = if (mode == @low ^ count ~= 0) then @mid else mode;
    };
    reward = sum_{?c : cell} [lit(?c) * WEIGHT(?c)] - 2 * count + -1;
    action-preconditions {
        forall_{?c : cell} [flip(?c) => ~lit(?c) | count < 5];
    };
    state-invariants {
        count >= 0;
        count > -1 ^ count <= SIZE;
    };
    constraints {
        (sum_{?c : cell} [flip(?c)]) <= 1;
    };
}
non-fluents nf_full {
    domain = full;
    objects {
        cell : {c1, c2};
        room : {kitchen};
    };
    non-fluents {
        SIZE = 4;
        WEIGHT(c1) = 2.5;
        WEIGHT(kitchen) = -1;
        ADJ(c1, c2);
        ~ADJ(c2, c1);
    };
}
instance inst_full {
    domain = full;
    non-fluents = nf_full;
    objects {
        cell : {c3};
    };
    init-state {
        ~lit(c3);
        count = 2;
        mode = @high;
    };
    max-nondef-actions = pos-inf;
    horizon = 40;
    discount = 0.9;
}
"""


def test_every_construct_reads() -> None:
    blocks = parse_rddl(FULL)
    domain, nf, instance = blocks.domain, blocks.non_fluents, blocks.instance
    assert domain is not None and nf is not None and instance is not None
    assert domain.types[2].parent is None and domain.types[2].values == ("@low", "@mid", "@high")
    assert domain.types[1].parent == Name("cell")
    heat = domain.pvariables[6]
    assert (heat.kind, heat.level, heat.default) == ("interm-fluent", 1, None)
    assert domain.pvariables[0].default == IntConst(-3)
    assert domain.pvariables[3].default == EnumValue("@low")
    assert [c.primed for c in domain.cpfs] == [False, False, True, True, True]
    assert domain.cpfs[0].expr == Binary(
        "+",
        Distribution("Normal", (Apply("WEIGHT", (p("?r"),)), RealConst(1.5))),
        Distribution("DiracDelta", (IntConst(2),)),
    )
    # The product reaches to the right: the multiplication is inside it.
    assert domain.cpfs[3].expr == Aggregate(
        "prod",
        (TypedParam("?c", Name("cell")),),
        Binary("*", If(Apply("lit", (p("?c"),)), IntConst(2), IntConst(1)), Neg(Apply("SIZE"))),
    )
    assert len(domain.action_preconditions) == 1 and len(domain.state_invariants) == 2
    assert len(domain.state_action_constraints) == 1
    assert nf.values[3].value == BoolConst(True) and nf.values[4].value == BoolConst(False)
    assert nf.values[2].value == IntConst(-1)
    assert instance.max_nondef_actions is None and instance.discount == 0.9
    assert instance.init_state[1].value == IntConst(2) and instance.init_state[2].value == EnumValue("@high")


@pytest.mark.parametrize(
    ("text", "expected"),
    [
        ("a ^ b | c", Binary("|", Binary("^", Apply("a"), Apply("b")), Apply("c"))),
        ("a | b & c", Binary("|", Apply("a"), Binary("&", Apply("b"), Apply("c")))),
        ("a => b => c", Binary("=>", Binary("=>", Apply("a"), Apply("b")), Apply("c"))),
        ("a <=> b => c", Binary("<=>", Apply("a"), Binary("=>", Apply("b"), Apply("c")))),
        ("~a == b", Not(Binary("==", Apply("a"), Apply("b")))),
        ("~a ^ b", Binary("^", Not(Apply("a")), Apply("b"))),
        ("a + b * c", Binary("+", Apply("a"), Binary("*", Apply("b"), Apply("c")))),
        ("a - b - c", Binary("-", Binary("-", Apply("a"), Apply("b")), Apply("c"))),
        ("-a * b", Binary("*", Neg(Apply("a")), Apply("b"))),
        ("-2 * b", Binary("*", IntConst(-2), Apply("b"))),
        ("-(2)", Neg(IntConst(2))),
        ("a < b + 1", Binary("<", Apply("a"), Binary("+", Apply("b"), IntConst(1)))),
        ("[a + b] * c", Binary("*", Binary("+", Apply("a"), Apply("b")), Apply("c"))),
        ("1.5e2 + .5", Binary("+", RealConst(150.0), RealConst(0.5))),
        ("if (a) then b else c + 1", If(Apply("a"), Apply("b"), Binary("+", Apply("c"), IntConst(1)))),
        (
            "exists_{?x : t} [f(?x)] ^ g",
            Aggregate("exists", (TypedParam("?x", Name("t")),), Binary("^", Apply("f", (p("?x"),)), Apply("g"))),
        ),
        ("f(?x, obj, @v)", Apply("f", (p("?x"), Apply("obj"), EnumValue("@v")))),
        ("x-y - z", Binary("-", Apply("x-y"), Apply("z"))),
    ],
)
def test_precedence_and_grouping(text: str, expected: object) -> None:
    assert parse_expr(text) == expected


def test_places_are_kept_but_not_compared() -> None:
    expr = parse_expr("a +\n  f(?x)")
    assert isinstance(expr, Binary)
    assert (expr.line, expr.column) == (1, 3)
    assert (expr.right.line, expr.right.column) == (2, 3)
    assert isinstance(expr.right, Apply) and (expr.right.args[0].line, expr.right.args[0].column) == (2, 5)
    assert parse_expr("a + f(?x)") == expr
