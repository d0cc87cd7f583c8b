"""What an import reports: notes on constructs without a counterpart, and located errors.

A *note* says what became of a construct of the designer's format that our
format does not have (a blackboard, a placeholder, a renamed element); the
element around it is still imported. An *error* refuses a whole file: it is
malformed (bad JSON, a value of the wrong type), refers to nothing, closes a
cycle of the plan tree, or depends on a refused file in a way that cannot be
dropped. Both name the designer file (relative to the source folder) and the
key inside it, e.g. ``states[2].confAbstractPlanWrappers[0].abstractPlan``.
"""

from __future__ import annotations

from dataclasses import dataclass
from enum import Enum


class Construct(Enum):
    """The kind of thing a note is about; the human summary groups notes by it."""

    RENAMED = "renamed"
    """A name that was not valid in our format, or clashed with another, was changed."""
    UNNAMED = "unnamed element"
    """An element with the designer's placeholder name (empty, ``MISSING_NAME``, its id) got one of ours."""
    PREDICATE = "condition as predicate"
    """A condition implemented in C++ is declared as a 0-ary predicate, to write as a formula or set with --fact."""
    STANDARD_CONDITION = "standard condition kept as predicate"
    """A standard-library condition whose inputs are not constants is declared as a predicate."""
    NO_CONDITION = "transition without condition"
    """A transition without a condition is imported with the condition ``false``."""
    DISABLED_CONDITION = "disabled condition"
    """A condition switched off in the designer (``enabled: false``) is not imported."""
    QUANTIFIER = "quantifier"
    """A condition's quantifiers and constraint variables have no counterpart."""
    LEGACY_CONDITION = "transition pre-condition"
    """The legacy inline condition object of a transition is not imported."""
    BLACKBOARD = "blackboard"
    """A typed blackboard (entries, inheritance) has no counterpart."""
    KEY_MAPPING = "key mapping"
    """A key mapping between blackboards (other than constants of standard conditions) has no counterpart."""
    CONFIGURATION = "configuration"
    """A wrapper's configuration has no counterpart."""
    EVENT_DRIVEN = "event-driven or deferring behaviour"
    """Event-driven and deferring behaviours have no counterpart; the behaviour is imported as a plain one."""
    PLACEHOLDER = "placeholder"
    """Placeholders and the children that refer to them have no counterpart."""
    DEACTIVATED = "deactivated plan in a plan type"
    """A plan a plan type lists with ``activated: false`` is left out of the type."""
    PLANTYPE_BINDING = "plan-type variables"
    """Variables and variable bindings of a plan type have no counterpart."""
    VARIABLE = "variable"
    """A variable's designer type is not kept, or a binding could not be imported."""
    ROLE = "role set"
    """Role characteristics and the default role set have no counterpart."""
    SETTINGS = "settings without counterpart"
    """Master plans, interfaces, implementation names, dynamic entry points, frequencies of the agent."""
    STRUCTURE = "unreachable or inconsistent"
    """States no entry point reaches, transitions out of terminal states, synchronisations of one transition."""
    DROPPED = "dropped reference"
    """A child, plan or priority that referred to a refused or unsupported element was left out."""
    REFERENCE = "reference"
    """A reference whose file name does not match the file holding its id (resolved by the id)."""
    AGENT_CONFIG = "agent config"
    """Settings of an agent config (``Alica.yaml``) and what they correspond to here."""
    OTHER_FILE = "other file"
    """A configuration file of the C++ engine without a counterpart (``UdpProxy.conf``)."""


@dataclass(frozen=True, slots=True)
class Note:
    """What became of one construct of one designer file.

    Args:
        file: the designer file, relative to the source folder (``plans/X.pml``).
        key: where in the file (``states[0].confAbstractPlanWrappers[1]``); empty for the whole file.
        construct: the kind of construct, for grouping.
        message: what was done and what to do about it.
    """

    file: str
    key: str
    construct: Construct
    message: str

    def format(self) -> str:
        """``file: key: message``."""
        where = f"{self.file}: {self.key}" if self.key else self.file
        return f"{where}: {self.message}"

    def sort_key(self) -> tuple[str, str, str, str]:
        """Notes are listed by file, key, construct and message."""
        return (self.file, self.key, self.construct.value, self.message)

    def as_json(self) -> dict[str, str]:
        """The note as a JSON object."""
        return {"file": self.file, "key": self.key, "construct": self.construct.value, "message": self.message}


@dataclass(frozen=True, slots=True, order=True)
class FileError:
    """Why a designer file was refused.

    Args:
        file: the designer file, relative to the source folder.
        key: where in the file; empty for the whole file.
        message: what is wrong.
        line: the line of a JSON syntax error (0 when not known).
        column: its column (0 when not known).
    """

    file: str
    key: str
    message: str
    line: int = 0
    column: int = 0

    def format(self) -> str:
        """``file:line:column: key: message``, with the parts that are known."""
        where = self.file + (f":{self.line}:{self.column}" if self.line else "")
        return f"{where}: {self.key}: {self.message}" if self.key else f"{where}: {self.message}"

    def as_json(self) -> dict[str, str | int]:
        """The error as a JSON object."""
        out: dict[str, str | int] = {"file": self.file, "key": self.key, "message": self.message}
        if self.line:
            out["line"] = self.line
            out["column"] = self.column
        return out
