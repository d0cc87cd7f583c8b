"""Skill plug-ins: modules that declare skills into a :class:`~alica.lang.skills.SkillRegistry`.

A plug-in is a module with a function ``register(registry)`` that declares
its skills::

    from alica import ParamSpec

    def register(registry):
        registry.declare("Wave", ParamSpec("times", "int", required=False, default=3),
                         doc="wave the arm", capabilities=("arm",), implementation=Wave)

Plug-ins are found two ways: by module name (``alica run --skills mymodule``,
:func:`load_skill_module`), and through the entry-point group ``alica.skills``
of installed packages (:func:`load_entry_points`); an entry point names a
module that has ``register`` or the ``register`` callable itself. The shipped
catalogue is such an entry point of this package, so the language layer never
imports the skills layer.
"""

from __future__ import annotations

import importlib
from collections.abc import Callable, Iterable
from types import ModuleType
from typing import Any

from alica.errors import AlicaError
from alica.lang.skills import SkillRegistry

__all__ = ["ENTRY_POINT_GROUP", "SkillPluginError", "default_registry", "load_entry_points", "load_skill_module"]

#: The entry-point group under which installed packages list their skill plug-ins.
ENTRY_POINT_GROUP = "alica.skills"


class SkillPluginError(AlicaError, ImportError):
    """A skill plug-in that cannot be loaded; the message names the module and says why."""


def _register_function(target: object, where: str) -> Callable[[SkillRegistry], object]:
    if isinstance(target, ModuleType):
        function = getattr(target, "register", None)
        if function is None:
            raise SkillPluginError(
                f"skill module '{where}' has no register(registry) function; define one that declares its skills"
            )
    else:
        function = target
    if not callable(function):
        raise SkillPluginError(f"skill module '{where}': register is not a function")
    return function


def _run_register(registry: SkillRegistry, function: Callable[[SkillRegistry], object], where: str) -> None:
    before = registry.origin
    registry.origin = where
    try:
        function(registry)
    except AlicaError as exc:
        raise SkillPluginError(f"skill module '{where}': {exc}") from exc
    except ValueError as exc:  # a clash with a declared skill or a bad parameter declaration
        raise SkillPluginError(f"skill module '{where}': {exc}") from exc
    except Exception as exc:  # the user's code failed: say where, in one line
        raise SkillPluginError(f"skill module '{where}': register() raised {type(exc).__name__}: {exc}") from exc
    finally:
        registry.origin = before


def load_skill_module(registry: SkillRegistry, module: str) -> None:
    """Import ``module`` and let its ``register(registry)`` declare its skills.

    Raises:
        SkillPluginError: the module cannot be imported, has no ``register``,
            declares a skill whose name is taken, or ``register`` raised.
    """
    name = module.strip()
    if not name:
        raise SkillPluginError("a skill module needs a name, e.g. --skills my_skills")
    try:
        imported = importlib.import_module(name)
    except ImportError as exc:
        raise SkillPluginError(
            f"skill module '{name}' cannot be imported: {exc} (is it on the Python path, or in the current folder?)"
        ) from exc
    except Exception as exc:  # the module's own code failed while importing
        raise SkillPluginError(f"skill module '{name}' failed while importing: {type(exc).__name__}: {exc}") from exc
    _run_register(registry, _register_function(imported, name), name)


def load_entry_points(registry: SkillRegistry, group: str = ENTRY_POINT_GROUP) -> None:
    """Load every plug-in installed packages list under the entry-point ``group``, in name order.

    Raises:
        SkillPluginError: an entry point cannot be loaded or its ``register`` fails.
    """
    import importlib.metadata  # here: reading the installed metadata costs ~25 ms at start-up

    found: Any = importlib.metadata.entry_points(group=group)
    for entry in sorted(found, key=lambda e: (e.name, e.value)):
        where = entry.value.partition(":")[0].strip()
        try:
            target = entry.load()
        except Exception as exc:  # an installed package's broken plug-in: say which, in one line
            dist = entry.dist.name if entry.dist is not None else None
            of = f" of package '{dist}'" if dist else ""
            raise SkillPluginError(
                f"skill module '{entry.value}' (entry point '{entry.name}'{of}) cannot be loaded: {type(exc).__name__}: {exc}"
            ) from exc
        _run_register(registry, _register_function(target, where), where)


def default_registry(modules: Iterable[str] = ()) -> SkillRegistry:
    """A fresh registry: the installed plug-ins (the shipped catalogue among them), then ``modules``.

    Args:
        modules: plug-in modules to load by name, in order (e.g. from ``--skills``).

    Raises:
        SkillPluginError: a plug-in cannot be loaded (the message names it).
    """
    registry = SkillRegistry()
    load_entry_points(registry)
    for module in dict.fromkeys(m.strip() for m in modules):
        load_skill_module(registry, module)
    return registry
