"""Bad RDDL raises RddlError with ``FILE:LINE:COL: error: ... (fix: ...)`` at the offending token."""

from __future__ import annotations

from pathlib import Path

import pytest

from alica.prophet.rddl import Domain, RddlError, parse_expr, parse_rddl, read_rddl, write_expr

BASE = """domain d {
    types {
        robot : object;
    };
    pvariables {
        COST(robot) : {non-fluent, real, default = 1};
        at(robot) : {state-fluent, bool, default = false};
        go(robot) : {action-fluent, bool, default = false};
    };
    cpfs {
        at'(?r) = go(?r) | at(?r);
    };
    reward = sum_{?r : robot} [go(?r) * COST(?r)];
}
"""
BLOCKS = """non-fluents nf {
    domain = d;
    objects {
        robot : {r1, r2};
    };
    non-fluents {
        COST(r1) = 2;
    };
}
instance i {
    domain = d;
    non-fluents = nf;
    init-state {
        at(r1);
    };
    max-nondef-actions = 1;
    horizon = 10;
    discount = 1.0;
}
"""


def domain() -> Domain:
    result = parse_rddl(BASE).domain
    assert result is not None
    return result


def error_of(text: str, **kwargs: Domain) -> str:
    with pytest.raises(RddlError) as caught:
        parse_rddl(text, **kwargs)
    return str(caught.value)


def test_the_sample_texts_are_valid() -> None:
    assert parse_rddl(BLOCKS, domain=domain()).instance is not None


@pytest.mark.parametrize(
    ("old", "new", "expected"),
    [
        (
            "    cpfs {",
            "    cpf {",
            "<string>:10:5: error: unknown keyword 'cpf' in a domain (fix: did you mean 'cpfs'?)",
        ),
        (
            "domain d {",
            "domian d {",
            "<string>:1:1: error: unknown keyword 'domian' at the top level (fix: did you mean 'domain'?)",
        ),
        ("\n}\n", "\n", "<string>:1:10: error: '{' is never closed (fix: add the '}' that closes it)"),
        ("\n}\n", "\n}\n}\n", "<string>:15:1: error: '}' closes nothing (fix: remove it or add the '{' it closes)"),
        (
            "[go(?r) * COST(?r)]",
            "[go(?r) * COST(?r])",
            "<string>:13:48: error: ']' does not match the '(' at 13:45 (fix: close the '(' with ')')",
        ),
        ("go(?r) | at(?r);", "(go(?r) | at(?r);", "<string>:12:5: error: '}' does not match the '(' at 11:19"),
        (
            "default = 1};",
            "default = 1}",
            "<string>:6:54: error: missing ';' after the declaration of 'COST', found 'at' (fix: add ';')",
        ),
        ("| at(?r);", "| at(?r)", "<string>:11:34: error: missing ';' after the cpf of 'at', found '}' (fix: add ';')"),
        (
            "| at(?r);",
            "| atx(?r);",
            "<string>:11:28: error: undeclared pvariable 'atx' in the cpf of 'at' (fix: did you mean 'at'?)",
        ),
        ("at'(?r)", "ta'(?r)", "<string>:11:9: error: cpf of the undeclared pvariable 'ta'"),
        ("at'(?r)", "at'(?r, ?s)", "<string>:11:9: error: 'at' takes 1 argument, the cpf has 2"),
        ("at'(?r)", "go(?r)", "<string>:11:9: error: the action-fluent 'go' takes no cpf (fix: remove the cpf)"),
        ("at'(?r)", "at(?r)", "<string>:11:9: error: the cpf of the state fluent 'at' needs a prime"),
        ("COST(?r)]", "COST(?r, ?r)]", "<string>:13:41: error: 'COST' takes 1 argument, 2 given in the reward"),
        ("COST(?r)]", "COSTS(?r)]", "<string>:13:41: error: undeclared pvariable 'COSTS' in the reward"),
        ("| at(?r);", "| at(?q);", "<string>:11:31: error: parameter '?q' is not bound in the cpf of 'at'"),
        ("reward = sum", "reward = COST(?r) + sum", "<string>:13:19: error: parameter '?r' is not bound in the reward"),
        ("at(robot)", "at(robt)", "<string>:7:12: error: unknown type 'robt' (fix: did you mean 'robot'?)"),
        ("{?r : robot}", "{?r : robots}", "<string>:13:24: error: unknown type 'robots' (fix: did you mean 'robot'?)"),
        (
            "bool, default = false};\n        go",
            "boolean};\n        go",
            "<string>:7:36: error: unknown type 'boolean'",
        ),
        ("state-fluent", "state-fluents", "<string>:7:22: error: unknown pvariable kind 'state-fluents'"),
        ("| at(?r);", "| at(?r) ^ @on;", "<string>:11:37: error: unknown enum value '@on' in the cpf of 'at'"),
        (
            "at'(?r) = go(?r)",
            "at'(?r) = go'(?r)",
            "<string>:11:19: error: 'go' is no state fluent and has no next value",
        ),
        (
            "at(robot) : {state",
            "at(robot) : {state-fluent, bool};\n        COST : {state",
            "<string>:8:9: error: pvariable 'COST' declared twice",
        ),
        ("robot : object;", "robot : thing;", "<string>:3:17: error: unknown type 'thing'"),
        ("domain d {", "domain det {", "<string>:1:8: error: 'det' is an RDDL keyword and cannot name a domain"),
        ("reward = sum", "reward = 1 $ sum", "<string>:13:16: error: unexpected character '$'"),
        (
            "reward = sum",
            "reward = then + sum",
            "<string>:13:14: error: expected an expression, found the keyword 'then'",
        ),
    ],
)
def test_domain_errors(old: str, new: str, expected: str) -> None:
    assert old in BASE
    message = error_of(BASE.replace(old, new, 1))
    assert message.startswith(expected), message


@pytest.mark.parametrize(
    ("old", "new", "expected"),
    [
        (
            "max-nondef-actions = 1;",
            "max-nondet-actions = 1;",
            "<string>:16:5: error: unknown keyword 'max-nondet-actions' in an instance"
            " (fix: did you mean 'max-nondef-actions'?)",
        ),
        (
            "instance i {",
            "instance det {",
            "<string>:10:10: error: 'det' is an RDDL keyword and cannot name an instance",
        ),
        ("COST(r1) = 2;", "COST(r0) = 2;", "<string>:7:14: error: unknown object 'r0' (fix: did you mean 'r"),
        ("at(r1);", "at(r3);", "<string>:14:12: error: unknown object 'r3'"),
        ("COST(r1) = 2;", "COST(r1, r2) = 2;", "<string>:7:9: error: 'COST' takes 1 argument, 2 given"),
        (
            "COST(r1) = 2;",
            "at(r1) = true;",
            "<string>:7:9: error: 'at' in 'non-fluents': state-fluent, expected a non-fluent",
        ),
        (
            "at(r1);",
            "COST(r1) = 3;",
            "<string>:14:9: error: 'COST' in 'init-state': non-fluent, expected a state-fluent",
        ),
        ("at(r1);", "~gone(r1);", "<string>:14:9: error: 'gone' in 'init-state': undeclared pvariable"),
        ("robot : {r1, r2};", "robots : {r1, r2};", "<string>:4:9: error: unknown type 'robots'"),
        ("robot : {r1, r2};", "robot : {r1, r1};", "<string>:4:22: error: object 'r1' declared twice"),
        (
            "    domain = d;\n    objects",
            "    domain = e;\n    objects",
            "<string>:2:14: error: domain 'e' is not the domain given, 'd'",
        ),
        (
            "non-fluents = nf;",
            "non-fluents = nf2;",
            "<string>:12:19: error: non-fluents 'nf2' is not the block given, 'nf'",
        ),
        (
            "horizon = 10;",
            "horizon = 10",
            "<string>:17:17: error: missing ';' after the 'horizon' section, found 'discount'",
        ),
        ("horizon = 10;", "horizon = 0;", "<string>:17:15: error: expected a whole number of at least 1 for 'horizon'"),
        ("discount = 1.0;", "discount = 1.5;", "<string>:18:16: error: expected a number from 0 to 1 for 'discount'"),
        ("horizon = 10;\n", "horizon = 10;\n    horizon = 5;\n", "<string>:18:5: error: a second 'horizon' section"),
        (
            "    domain = d;\n    non-fluents =",
            "    non-fluents =",
            "<string>:10:10: error: an instance 'i' names no domain",
        ),
    ],
)
def test_non_fluents_and_instance_errors(old: str, new: str, expected: str) -> None:
    assert old in BLOCKS
    message = error_of(BLOCKS.replace(old, new, 1), domain=domain())
    assert message.startswith(expected), message


PAPER_INSTANCE = """non-fluents nf_multi_ros_robot_inst_mdp__1 {
domain = multi_ros_robot_mdp;
objects {
robot : { r1,r2};
xPos : { x1,x2};
yPos : { y1,y2};
};
non-fluents {
PROB_GOTO(r1) = 0.9;
GOTO_COST(x1, y1, xGoto1, yGoto1) = 0;
};
}
"""


def test_the_papers_typos_are_reported() -> None:
    paper = read_rddl(Path(__file__).parent / "data" / "multi_ros_robot_mdp.rddl").domain
    assert paper is not None
    message = error_of(PAPER_INSTANCE, domain=paper)
    assert message == "<string>:10:19: error: unknown object 'xGoto1' (fix: did you mean 'x1'?)"
    instance = "instance i {\ndomain = multi_ros_robot_mdp;\nmax-nondet-actions = 4;\n}\n"
    assert error_of(instance, domain=paper).startswith(
        "<string>:3:1: error: unknown keyword 'max-nondet-actions' in an instance (fix: did you mean 'max-nondef-actions'?)"
    )


def test_expression_errors() -> None:
    with pytest.raises(RddlError, match=r"^<string>:1:7: error: unexpected 'b' after the expression"):
        parse_expr("a + b b")
    with pytest.raises(RddlError, match=r"^<string>:1:12: error: expected an expression, found the end of the text"):
        parse_expr("if (a) then")
    with pytest.raises(RddlError, match=r"^<string>:1:7: error: expected a parameter '\?name', found 't'"):
        parse_expr("sum_{ t : u } [1]")


def test_deep_nesting_raises_rddl_error() -> None:
    deep = "(" * 5000 + "a" + ")" * 5000
    with pytest.raises(RddlError, match=r"^<string>:1:\d+: error: the expression is nested too deeply to read"):
        parse_expr(deep)
    with pytest.raises(RddlError, match=r"^<string>:13:\d+: error: the expression is nested too deeply to read"):
        parse_rddl(BASE.replace("reward = sum", f"reward = {deep} + sum"))
    assert parse_expr("(" * 150 + "a" + ")" * 150) == parse_expr("a")
    chain = "".join(f"if (c{i}) then {i} else " for i in range(150)) + "0"
    assert write_expr(parse_expr(chain)).count("else if") == 149


def test_read_rddl_gives_the_file_in_the_place(tmp_path: Path) -> None:
    broken = tmp_path / "broken.rddl"
    broken.write_text(BASE.replace("| at(?r);", "| at(?q);"), encoding="utf-8")
    with pytest.raises(RddlError) as caught:
        read_rddl(broken)
    assert str(caught.value).startswith(f"{broken}:11:31: error: parameter '?q' is not bound")
    assert caught.value.span is not None and caught.value.span.line == 11


def test_read_rddl_unreadable_and_not_utf8(tmp_path: Path) -> None:
    with pytest.raises(RddlError, match=r"^error: cannot read .*missing\.rddl"):
        read_rddl(tmp_path / "missing.rddl")
    latin = tmp_path / "latin.rddl"
    latin.write_bytes(b"domain d {\n  // caf\xe9\n}\n")
    with pytest.raises(RddlError) as caught:
        read_rddl(latin)
    assert str(caught.value) == f"{latin}:2:9: error: the file is not UTF-8 text (byte 0xe9) (fix: save it as UTF-8)"
