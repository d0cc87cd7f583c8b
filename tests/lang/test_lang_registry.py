"""Registry, built-ins and static checks."""

from __future__ import annotations

import pytest

from alica.lang import Registry, check, default_registry, parse


def test_register_and_lookup() -> None:
    registry = Registry()
    entry = registry.register("near", lambda a, b: True, 2, doc="near(a, b)")
    assert "near" in registry
    assert registry.get("near") is entry
    assert registry.get("far") is None
    assert entry.kind == "predicate"
    assert (entry.min_arity, entry.max_arity) == (2, 2)
    assert len(registry) == 1
    assert [e.name for e in registry] == ["near"]


def test_duplicate_registration_is_an_error() -> None:
    registry = Registry()
    registry.register("near", lambda a, b: True, 2)
    with pytest.raises(ValueError, match="already registered"):
        registry.register("near", lambda a, b: False, 2)
    registry.register("near", lambda a, b: False, 3, replace=True)
    assert registry.get("near").min_arity == 3  # type: ignore[union-attr]


def test_decorators() -> None:
    registry = Registry()

    @registry.predicate("MaxDist", arity=3, needs_belief=True)
    def max_dist(belief: object, a: object, b: object, d: float) -> bool:
        """Far apart."""
        return True

    @registry.function("twice", arity=1)
    def twice(x: float) -> float:
        return 2 * x

    assert twice(2) == 4  # the decorator returns the function
    assert registry.get("MaxDist").needs_belief  # type: ignore[union-attr]
    assert registry.get("MaxDist").doc == "Far apart."  # type: ignore[union-attr]
    assert registry.get("twice").kind == "function"  # type: ignore[union-attr]
    with pytest.raises(ValueError):
        registry.function("twice", arity=1)(twice)


@pytest.mark.parametrize("name", ["", "and", "1x", "a-b", "has space", "?"])
def test_invalid_names(name: str) -> None:
    with pytest.raises(ValueError):
        Registry().register(name, abs, 1)


@pytest.mark.parametrize("arity", [-1, (2, 1), (-1, None), "2", (1, 2, 3), True])
def test_invalid_arities(arity: object) -> None:
    with pytest.raises(ValueError):
        Registry().register("f", abs, arity)  # type: ignore[arg-type]


def test_invalid_kind_and_callable() -> None:
    with pytest.raises(ValueError):
        Registry().register("f", abs, 1, kind="macro")
    with pytest.raises(ValueError):
        Registry().register("f", 3, 1)  # type: ignore[arg-type]


def test_arity_ranges() -> None:
    registry = Registry()
    variadic = registry.register("v", max, (1, None))
    ranged = registry.register("r", round, (1, 2))
    assert variadic.accepts(1) and variadic.accepts(10) and not variadic.accepts(0)
    assert ranged.accepts(2) and not ranged.accepts(3)
    assert variadic.arity_text() == "at least 1 argument"
    assert ranged.arity_text() == "1 to 2 arguments"


def test_copy_is_independent() -> None:
    registry = default_registry()
    other = registry.copy()
    other.register("extra", abs, 1)
    assert "extra" in other and "extra" not in registry
    assert "MaximalDist" in other
    registry.unregister("sqrt")
    assert "sqrt" in other


def test_default_registry_is_fresh_and_complete() -> None:
    first, second = default_registry(), default_registry()
    assert first is not second
    first.register("mine", abs, 1)
    assert "mine" not in second
    for name in [
        "sqrt",
        "abs",
        "min",
        "max",
        "dist",
        "floor",
        "ceil",
        "round",
        "count",
        "MaximalDist",
        "MinimalDist",
    ]:
        assert name in second
    assert second.get("count").needs_belief  # type: ignore[union-attr]
    assert second.get("MaximalDist").kind == "predicate"  # type: ignore[union-attr]


# -- check ------------------------------------------------------------------


def test_check_accepts_valid_formulas() -> None:
    registry = default_registry()
    for text in [
        "forall f1, f2 in Frontier: MaximalDist(f1, f2, eps) or f1 = f2",
        "count(Sample) >= 2",
        "min(1, 2, 3) < max(xs)",
        "Unknown(a, b, c, d) and other",
        "round(x) = round(x, 2)",
    ]:
        assert check(parse(text), registry, text=text) == []


def test_check_reports_wrong_arity_at_call_column() -> None:
    text = "a and MaximalDist(f1, f2)"
    errors = check(parse(text), default_registry(), text=text)
    assert len(errors) == 1
    assert errors[0].column == 7
    assert "MaximalDist takes 3 arguments, got 2" in errors[0].message
    assert errors[0].text == text
    assert errors[0].hint


def test_check_reports_every_problem() -> None:
    text = "sqrt() > 0 or min() < 1 or round(1, 2, 3) = 1"
    errors = check(text, default_registry())
    assert [e.column for e in errors] == [1, 15, 28]


def test_check_without_registry_checks_no_arities() -> None:
    assert check("MaximalDist(a)") == []
    assert len(check("MaximalDist(a)", default_registry())) == 1


@pytest.mark.parametrize(
    ("text", "column", "fragment"),
    [
        ("forall x, x in T: p(x)", 1, "bound twice"),
        ("a and 1", 7, "not a truth value"),
        ("'yes'", 1, "not a truth value"),
        ("x + 1", 1, "not a truth value"),
        ("not (x - 1)", 6, "not a truth value"),
        ("x + 'a' > 0", 5, "not a number"),
        ("(a and b) * 2 > 0", 2, "not a number"),
        ("-true < 0", 2, "not a number"),
        ("(a < b) < c", 2, "cannot be ordered"),
    ],
)
def test_check_decidable_type_errors(text: str, column: int, fragment: str) -> None:
    errors = check(text, default_registry(), boolean=True)
    assert len(errors) == 1, errors
    assert errors[0].column == column
    assert fragment in errors[0].message


def test_check_term_mode_is_the_default() -> None:
    assert check("x + 1") == []
    assert check("1 - dist(pos(self), goal) / 10", default_registry()) == []
    assert len(check("x + 1", boolean=True)) == 1
    assert check("(a < b) = true", boolean=True) == []
    assert len(check("a and 1")) == 1  # operands of connectives are always checked
