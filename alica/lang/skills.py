"""The skill vocabulary: what each skill is called, which parameters it takes, what runs it.

Declarations are plain data so ``alica validate`` can check plan files
without importing pybullet, OMPL or FCL. Each declaration names its
implementation as ``"module:attribute"`` (imported only when asked for) or
gives the py_trees behaviour class itself. The shipped catalogue
(:mod:`alica.skills.catalog`) and users' plug-ins register into a
:class:`SkillRegistry`; :mod:`alica.lang.skill_plugins` finds and loads them.
"""

from __future__ import annotations

import dataclasses
import importlib
from collections.abc import Callable, Iterator, Mapping
from dataclasses import dataclass, field
from typing import Any

from alica.errors import UnknownSkillError
from alica.lang.vocabulary import Symbol, Vocabulary, default_vocabulary
from alica.source import SourceSpan

#: Parameter types a skill may declare, with what a literal value of each must be.
PARAM_TYPES: dict[str, str] = {
    "float": "a number",
    "int": "a whole number",
    "bool": "true or false",
    "str": "text",
    "object": "an object name",
    "position": "a list [x, y] or [x, y, z] of numbers, or a term such as pos(a)",
    "pose": "a list [x, y, yaw] of numbers, or a term such as pose(a)",
    "list": "a list",
    "any": "any value",
}


@dataclass(frozen=True, slots=True)
class ParamSpec:
    """One parameter a skill takes.

    Args:
        name: the key used in a behaviour's ``params``.
        type: one of :data:`PARAM_TYPES`.
        required: whether a behaviour must give it.
        default: the value used when it is not given.
        doc: one line for ``alica list-skills``.
    """

    name: str
    type: str = "any"
    required: bool = True
    default: object = None
    doc: str = ""

    def __post_init__(self) -> None:
        if self.type not in PARAM_TYPES:
            raise ValueError(f"parameter '{self.name}': unknown type '{self.type}', use one of {sorted(PARAM_TYPES)}")
        if self.required and self.default is not None:
            raise ValueError(f"parameter '{self.name}': a required parameter has no default")

    def check(self, value: object) -> str | None:
        """Why a literal ``value`` does not fit this parameter, or ``None`` if it does.

        ``$name`` variable references always fit: they are checked at run time.
        """
        if isinstance(value, str) and value.startswith("$"):
            return None
        ok = {
            "float": lambda v: isinstance(v, (int, float)) and not isinstance(v, bool),
            "int": lambda v: isinstance(v, int) and not isinstance(v, bool),
            "bool": lambda v: isinstance(v, bool),
            "str": lambda v: isinstance(v, str),
            "object": lambda v: isinstance(v, str) and bool(v.strip()),
            "position": lambda v: isinstance(v, str) or _numbers(v, (2, 3)),
            "pose": lambda v: isinstance(v, str) or _numbers(v, (3,)),
            "list": lambda v: isinstance(v, tuple),
            "any": lambda v: True,
        }[self.type]
        if ok(value):
            return None
        return f"must be {PARAM_TYPES[self.type]}"


def _numbers(value: object, lengths: tuple[int, ...]) -> bool:
    return (
        isinstance(value, tuple)
        and len(value) in lengths
        and all(isinstance(v, (int, float)) and not isinstance(v, bool) for v in value)
    )


@dataclass(frozen=True, slots=True)
class SkillSpec:
    """A skill's declaration.

    Args:
        name: the name plan files use in ``skill:``.
        params: the parameters it takes.
        doc: one line saying what it does.
        capabilities: what a robot needs to run it (e.g. ``arm``).
        implementation: the py_trees behaviour class (or factory) constructed as
            ``Cls(name, params, context)``, or its ``"module:attribute"``, or
            ``None`` if not implemented yet.
        origin: where the declaration came from: ``alica`` for the shipped
            catalogue, else the plug-in module (set by the registry while a
            plug-in registers), or the plan file that declared it.
        declared_at: where a plan file's ``skills:`` section declared it
            (:mod:`alica.io.skill_declarations`); ``None`` for a declaration
            made in Python. A file-declared skill has no implementation: a
            ``--skills MODULE`` whose ``register(registry)`` declares the same
            name with one takes its place.
    """

    name: str
    params: tuple[ParamSpec, ...] = ()
    doc: str = ""
    capabilities: frozenset[str] = frozenset()
    implementation: str | Callable[..., Any] | None = None
    origin: str = ""
    declared_at: SourceSpan | None = None

    def param(self, name: str) -> ParamSpec | None:
        """The parameter called ``name``, if declared."""
        for p in self.params:
            if p.name == name:
                return p
        return None

    @property
    def implementation_name(self) -> str | None:
        """The implementation as ``"module:attribute"``, or ``None`` when there is none."""
        impl = self.implementation
        if impl is None or isinstance(impl, str):
            return impl
        return f"{getattr(impl, '__module__', '?')}:{getattr(impl, '__qualname__', repr(impl))}"


@dataclass
class SkillRegistry:
    """Skill declarations by name.

    Attributes:
        origin: stamped on declarations that name no origin of their own (the
            plug-in loader sets it to the module while the module registers).
    """

    _specs: dict[str, SkillSpec] = field(default_factory=dict)
    origin: str = ""
    facts: Vocabulary = field(default_factory=default_vocabulary)
    """The predicates and functions conditions may read: the engine's own, and what the skills write."""

    def declare_predicate(self, name: str, arity: int, doc: str = "") -> Symbol:
        """Declare a predicate a skill writes to the world model (``found/1``), so plans may read it undeclared.

        Raises:
            ValueError: the name is declared as a function, or is not a name.
        """
        return self.facts.declare_predicate(name, arity, doc, origin=self.origin)

    def declare_function(self, name: str, arity: int, doc: str = "") -> Symbol:
        """Declare a function (a value, such as ``pos/1``) a skill writes; see :meth:`declare_predicate`."""
        return self.facts.declare_function(name, arity, doc, origin=self.origin)

    def register(self, spec: SkillSpec, *, replace: bool = False) -> SkillSpec:
        """Add a declaration.

        Raises:
            ValueError: the name is taken and ``replace`` is false, or two
                parameters share a name.
        """
        if spec.name in self._specs and not replace:
            taken = self._specs[spec.name].origin
            raise ValueError(f"skill '{spec.name}' is already registered" + (f" by {taken}" if taken else ""))
        names = [p.name for p in spec.params]
        if len(names) != len(set(names)):
            raise ValueError(f"skill '{spec.name}' declares a parameter twice")
        if not spec.origin and self.origin:
            spec = dataclasses.replace(spec, origin=self.origin)
        self._specs[spec.name] = spec
        return spec

    def declare(
        self,
        name: str,
        *params: ParamSpec,
        doc: str = "",
        capabilities: tuple[str, ...] | frozenset[str] = (),
        implementation: str | Callable[..., Any] | None = None,
    ) -> SkillSpec:
        """Register a skill from its parts; the one-line way to declare one.

        Args:
            name: the name plan files use in ``skill:``.
            params: the parameters it takes.
            doc: one line saying what it does.
            capabilities: what a robot needs to run it (e.g. ``("base",)``).
            implementation: the py_trees behaviour class, constructed as
                ``Cls(name, params, context)``, or its ``"module:attribute"``.

        Raises:
            ValueError: the name is taken, or two parameters share a name.
        """
        return self.register(SkillSpec(name, tuple(params), doc, frozenset(capabilities), implementation))

    def __contains__(self, name: object) -> bool:
        return name in self._specs

    def __iter__(self) -> Iterator[SkillSpec]:
        return iter(sorted(self._specs.values(), key=lambda s: s.name))

    def __len__(self) -> int:
        return len(self._specs)

    def get(self, name: str) -> SkillSpec:
        """The declaration of ``name``.

        Raises:
            UnknownSkillError: no skill has that name.
        """
        try:
            return self._specs[name]
        except KeyError:
            raise UnknownSkillError(f"no skill named '{name}' is registered") from None

    def names(self) -> list[str]:
        """All skill names, sorted."""
        return sorted(self._specs)

    def copy(self) -> SkillRegistry:
        """An independent registry with the same declarations and facts."""
        return SkillRegistry(dict(self._specs), self.origin, self.facts.copy())

    def load(self, name: str) -> Callable[..., Any]:
        """Import and return the implementation of ``name``, as a factory ``(name, params, context)``.

        The parameters the factory is given are completed with the declared
        defaults (those that are not ``None``) of the parameters a plan leaves
        out, so a skill reads ``params["tolerance"]`` whether it runs in a
        team (``alica run``) or alone (:func:`alica.skills.testing.run_skill`).
        A skill that declares no such default gets its implementation itself.

        Raises:
            UnknownSkillError: no such skill, no implementation declared, or
                its module cannot be imported (the message says why).
        """
        spec = self.get(name)
        if spec.implementation is None:
            raise UnknownSkillError(unimplemented(spec))
        if not isinstance(spec.implementation, str):
            return _with_defaults(spec.implementation, spec)
        module_name, _, attribute = spec.implementation.partition(":")
        try:
            module = importlib.import_module(module_name)
        except ImportError as exc:
            raise UnknownSkillError(
                f"skill '{name}' needs module '{module_name}', which cannot be imported: {exc}"
            ) from exc
        try:
            implementation = getattr(module, attribute)
        except AttributeError:
            raise UnknownSkillError(f"skill '{name}': module '{module_name}' has no '{attribute}'") from None
        return _with_defaults(implementation, spec)


def unimplemented(spec: SkillSpec) -> str:
    """Why ``spec`` cannot run, and how to give it an implementation."""
    where = f" in {spec.declared_at}" if spec.declared_at is not None else ""
    return (
        f"skill '{spec.name}' is declared{where} but has no implementation yet; bind one with --skills MODULE, "
        f"a module whose register(registry) declares '{spec.name}' with an implementation, "
        "or run scripted stand-ins with --stand-ins"
    )


def _with_defaults(implementation: Callable[..., Any], spec: SkillSpec) -> Callable[..., Any]:
    """``implementation``, given ``spec``'s declared defaults for the parameters left out."""
    defaults = {p.name: p.default for p in spec.params if not p.required and p.default is not None}
    if not defaults:
        return implementation

    def build(name: str, params: Mapping[str, object], context: Any) -> Any:
        return implementation(name, {**defaults, **params}, context)

    build.__name__ = build.__qualname__ = getattr(implementation, "__name__", spec.name)
    build.__doc__ = getattr(implementation, "__doc__", None)
    build.__wrapped__ = implementation  # type: ignore[attr-defined]
    return build
