"""The ``skills:`` section of plan files: a skill catalogue written as data.

A plan file may declare skills the way a Python plug-in's ``register(registry)``
does, without an implementation::

    skills:
      - name: Attack
        doc: "imported from the ALICA Plan Designer: behaviour Attack"
        capabilities: [arm]
        params:
          - {name: goal, type: str, required: false, default: "", doc: "where to go"}

Semantics, stated here and in ``docs/plan_format.md`` ("Skill declarations"):

* A declaration is visible to every file of the document set, like a task.
  Behaviours may name a declared skill in ``skill:``, and their ``params`` are
  checked against its parameters exactly as for a skill declared in Python.
* The registry the loader is given (the shipped catalogue, installed plug-ins,
  ``--skills MODULE``) wins: a name it declares in Python keeps that declaration
  and the file's is ignored. This is how ``--skills my_module`` binds an
  implementation to a skill a plan file declared.
* Two declarations of one name in the document set are a duplicate, reported
  at the second like any other duplicate name.
* A file-declared skill has no implementation. :meth:`alica.io.Loader.load`
  adds the set's declarations to the registry it was given
  (:func:`declare_skills`), so whatever builds skills from that registry at run
  time (``alica run``, ``alica agent``, the engine's ``SkillBinder``, the
  scripted stand-ins of ``--stand-ins``) sees them as declared skills without
  an implementation.

Malformed entries (an unknown key, a missing name, an unknown parameter type, a
default of the wrong type, a required parameter with a default, two parameters
of one name) are reported at their place by :func:`build_skills`; the bad part
is left out, so the declarations it returns always make valid
:class:`~alica.lang.skills.ParamSpec` objects.
"""

from __future__ import annotations

from collections.abc import Iterable

from alica.io.fields import Fields, Problems, kind_of, suggest
from alica.io.tree import Node
from alica.io.xml_vocabulary import resolve_scalar
from alica.lang.skills import PARAM_TYPES, ParamSpec, SkillRegistry, SkillSpec
from alica.model import ParamValue, SkillDeclaration, SkillParameter

#: Keys of one entry of ``skills:``.
SKILL_KEYS = ("name", "doc", "capabilities", "params")
#: Keys of one parameter of a declared skill.
PARAMETER_KEYS = ("name", "type", "required", "default", "doc")
#: Parameter types whose default, written as text (an XML attribute), is read as a YAML scalar.
_SCALAR_TYPES = ("float", "int", "bool")


def build_skills(top: Fields, problems: Problems) -> tuple[SkillDeclaration, ...]:
    """The declarations of a file's ``skills:`` section; problems go to ``problems``."""
    out = []
    for node in top.items("skills"):
        declaration = _skill(node, problems)
        if declaration is not None:
            out.append(declaration)
    return tuple(out)


def _label(node: Node) -> str | None:
    name = node.value.get("name") if isinstance(node.value, dict) else None
    return str(name.value).strip() if name is not None and isinstance(name.value, (str, int, float)) else None


def _skill(node: Node, problems: Problems) -> SkillDeclaration | None:
    if not node.is_mapping:
        problems.add(
            node.span,
            f"each entry of 'skills' must be a mapping with a 'name', not {kind_of(node)}",
            "write '- name: MySkill' with its 'doc', 'capabilities' and 'params'",
        )
        return None
    label = _label(node)
    f = Fields(node, f"skill '{label}'" if label else "a skill", problems, SKILL_KEYS)
    name = f.name()
    params: list[SkillParameter] = []
    first: dict[str, SkillParameter] = {}
    for item in f.items("params", hint="write '- {name: goal, type: str}' for each parameter"):
        param = _parameter(item, f.what, problems)
        if param is None:
            continue
        earlier = first.get(param.name)
        if earlier is not None:
            at = f" (the first is at line {earlier.span.line})" if earlier.span is not None else ""
            problems.add(
                param.span, f"{f.what} has two parameters named '{param.name}'{at}", "give each parameter its own name"
            )
            continue
        first[param.name] = param
        params.append(param)
    capabilities = frozenset(n for n, _ in f.names("capabilities", hint="list capabilities by name, e.g. [arm]"))
    return SkillDeclaration(name, tuple(params), f.text("doc"), capabilities, span=node.span)


def _parameter(node: Node, skill: str, problems: Problems) -> SkillParameter | None:
    if not node.is_mapping:
        problems.add(
            node.span,
            f"each parameter of {skill} must be a mapping with a 'name', not {kind_of(node)}",
            "write '- {name: goal, type: str, required: false, default: \"\"}'",
        )
        return None
    label = _label(node)
    f = Fields(
        node, f"parameter '{label}' of {skill}" if label else f"a parameter of {skill}", problems, PARAMETER_KEYS
    )
    name = f.name()
    kind = f.text("type", default="any").strip()
    if kind not in PARAM_TYPES:
        problems.add(
            f.span_of("type"),
            f"{f.what} has unknown type '{kind}'",
            suggest(kind, PARAM_TYPES) or "use one of " + ", ".join(PARAM_TYPES),
        )
        kind = "any"
    default = _default(f, kind, problems)
    required = f.flag("required", default is None)
    if required and default is not None:
        problems.add(
            f.span_of("default"),
            f"{f.what} is required, so it takes no default",
            "write 'required: false' to give it a default, or remove 'default'",
        )
        default = None
    return SkillParameter(name, kind, required, default, f.text("doc"), span=node.span)


def _default(f: Fields, kind: str, problems: Problems) -> ParamValue:
    """The parameter's default, read by its type; ``None`` when there is none or it does not fit."""
    node = f.get("default")
    if node is None or node.value is None:
        return None
    value = _value(node, f.what, problems)
    if value is None:
        return None
    value = coerce_default(value, kind)
    # ParamSpec.check lets any '$name' pass (a behaviour's variable, bound at run time); a default has no
    # variables to refer to, so '$x' is checked as the text 'x' and fits only a type that takes text.
    probe = value[1:] if isinstance(value, str) and value.startswith("$") else value
    reason = ParamSpec("default", kind, required=False).check(probe)
    if reason is not None:
        problems.add(
            node.span, f"default of {f.what} {reason}, not {value!r}", f"write a default of type {kind}, or remove it"
        )
        return None
    return value


def _value(node: Node, what: str, problems: Problems) -> ParamValue:
    """A default as written: a scalar, or a list (of lists) of scalars as tuples."""
    if isinstance(node.value, list):
        items = [_value(item, what, problems) for item in node.value]
        return tuple(items)
    if isinstance(node.value, dict):
        problems.add(node.span, f"default of {what} must be a value or a list, not a mapping", "write one value")
        return None
    return node.value


def coerce_default(value: ParamValue, kind: str) -> ParamValue:
    """A default given as text, read by the parameter's type.

    XML attributes are text: ``default="0.3"`` of a float parameter is the
    number 0.3, ``default="true"`` of a bool parameter is true (YAML 1.1 scalar
    rules). Text of any other type, and values that are not text, stay as they are.
    """
    if isinstance(value, str) and kind in _SCALAR_TYPES:
        resolved = resolve_scalar(value.strip())
        if resolved is not None and not isinstance(resolved, str):
            return resolved
    return value


# --------------------------------------------------------------------------- the registry


def skill_spec(declaration: SkillDeclaration) -> SkillSpec:
    """The :class:`SkillSpec` of a file's declaration: no implementation, ``declared_at`` its place.

    Raises:
        ValueError: a parameter :class:`ParamSpec` refuses (not one :func:`build_skills` made).
    """
    params = tuple(ParamSpec(p.name, p.type, p.required, p.default, p.doc) for p in declaration.params)
    span = declaration.span
    return SkillSpec(
        declaration.name,
        params,
        declaration.doc,
        declaration.capabilities,
        None,
        origin=span.file if span is not None else "a plan file",
        declared_at=span,
    )


def with_declarations(
    registry: SkillRegistry, declarations: Iterable[SkillDeclaration], problems: Problems
) -> SkillRegistry:
    """The skills a document set's behaviours may use: ``registry``'s Python declarations and the set's own.

    A skill ``registry`` holds only because an earlier :func:`declare_skills`
    put it there (another document set's file declaration) is left out, so a
    set sees the file declarations of its own files only. ``declarations``
    must have unique names (the validator reports duplicates).

    Returns:
        A new registry; ``registry`` is not changed.
    """
    python = {spec.name: spec for spec in registry if spec.declared_at is None}
    view = SkillRegistry(python, "", registry.facts.copy())
    for declaration in declarations:
        if declaration.name in view:
            continue  # the registry's declaration wins: that is how --skills binds an implementation
        try:
            view.register(skill_spec(declaration))
        except ValueError as exc:
            problems.add(declaration.span, f"skill '{declaration.name}': {exc}", "fix the skill's parameters")
    return view


def declare_skills(registry: SkillRegistry, declarations: Iterable[SkillDeclaration]) -> None:
    """Add a loaded set's file declarations to ``registry`` for the run that follows.

    A name ``registry`` declares in Python keeps its declaration; one an earlier
    load declared from a file is replaced by this set's.
    """
    for declaration in declarations:
        if declaration.name in registry and registry.get(declaration.name).declared_at is None:
            continue
        registry.register(skill_spec(declaration), replace=True)
