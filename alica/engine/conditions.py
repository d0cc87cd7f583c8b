"""Formulas of plans compiled once and evaluated against an agent's belief base."""

from __future__ import annotations

from collections.abc import Callable, Mapping

from alica.errors import AlicaError
from alica.lang import BeliefBase, Registry, compile_formula

#: A compiled formula: its value (or truth) for a belief base and the plan's variables.
Compiled = Callable[[BeliefBase, Mapping[str, object]], object]


class Formulas:
    """Compiled formulas by text, for one registry of predicates and functions.

    A formula that cannot be evaluated (an :class:`~alica.errors.AlicaError`
    while evaluating) counts as false and is reported once through ``on_error``
    with the formula and the message, so a bad condition is visible without
    stopping the team.
    """

    def __init__(self, registry: Registry | None = None, on_error: Callable[[str, str], None] | None = None) -> None:
        self.registry = registry
        self.on_error = on_error
        self._truth: dict[str, Compiled] = {}
        self._value: dict[str, Compiled] = {}
        self._reported: set[tuple[str, str]] = set()

    def holds(self, text: str | None, belief: BeliefBase, env: Mapping[str, object]) -> bool:
        """Whether ``text`` holds (``None``: the empty condition, true)."""
        if text is None:
            return True
        run = self._truth.get(text)
        if run is None:
            run = self._truth[text] = compile_formula(text, self.registry, boolean=True)
        try:
            return bool(run(belief, env))
        except AlicaError as exc:
            self._report(text, str(exc))
            return False

    def value(self, text: str, belief: BeliefBase, env: Mapping[str, object]) -> object:
        """The value of a term.

        Raises:
            AlicaError: the term cannot be evaluated.
        """
        run = self._value.get(text)
        if run is None:
            run = self._value[text] = compile_formula(text, self.registry, boolean=False)
        return run(belief, env)

    def _report(self, text: str, message: str) -> None:
        if (text, message) in self._reported:
            return
        self._reported.add((text, message))
        if self.on_error is not None:
            self.on_error(text, message)
