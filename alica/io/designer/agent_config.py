"""The C++ engine's agent configs (``Alica.yaml``) and other config files: what they correspond to here.

Nothing of them is written: our engine's settings are options of ``alica
run`` and ``alica agent`` and fields of :class:`alica.engine.EngineConfig`.
Each setting with a counterpart gets a note naming it; the others are listed
in one note.
"""

from __future__ import annotations

import yaml

from alica.io.designer.report import Construct, FileError, Note

# setting -> (counterpart, scale): the value is multiplied by scale (ms -> s), or inverted for 1/x
_ALICA: dict[str, tuple[str, str]] = {
    "TeamTimeOut": ("the team timeout: EngineConfig(team_timeout={s})", "ms"),
    "AssignmentProtectionTime": ("EngineConfig(assignment_protection={s})", "ms"),
    "AutoFailureHandling": (
        "automatic failure handling: the option --auto-failure-handling on|off of alica run and alica agent "
        "(EngineConfig(auto_failure_handling={v}))",
        "",
    ),
    "EngineFrequency": ("the engine's rate: alica run --frequency {v}", ""),
    "MinBroadcastFrequency": ("EngineConfig(broadcast_interval={inv}) (a team message at least this often)", ""),
    "MaxBroadcastFrequency": ("EngineConfig(min_broadcast_gap={inv}) (a team message at most this often)", ""),
    "MaxRuleApplications": ("EngineConfig(max_rule_applications={v})", ""),
    "AllowIdling": ("EngineConfig(allow_idle={v})", ""),
}
_CYCLES: dict[str, tuple[str, str]] = {
    "CycleCount": ("EngineConfig(cycle_count={v})", ""),
    "MinimalAuthorityTimeInterval": ("EngineConfig(authority_min={s})", "ms"),
    "MaximalAuthorityTimeInterval": ("EngineConfig(authority_max={s})", "ms"),
    "IntervalIncreaseFactor": ("EngineConfig(authority_growth={v})", ""),
}


def _shown(value: object) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    return str(value)


def _counterpart(template: str, value: object) -> str:
    number = value if isinstance(value, (int, float)) and not isinstance(value, bool) else None
    seconds = f"{number / 1000:g}" if number is not None else "?"
    inverse = f"{1 / number:g}" if number else "?"
    shown = ("True" if value else "False") if isinstance(value, bool) else _shown(value)
    return template.format(s=seconds, v=shown, inv=inverse)


def agent_config_notes(text: str, file: str) -> tuple[list[Note], list[FileError]]:
    """Notes on the settings of one ``Alica.yaml``; an error when it cannot be read."""
    try:
        data: object = yaml.safe_load(text)
    except yaml.MarkedYAMLError as exc:
        mark = exc.problem_mark or exc.context_mark
        line, column = (mark.line + 1, mark.column + 1) if mark is not None else (0, 0)
        return [], [FileError(file, "", f"bad YAML: {exc.problem or exc}", line, column)]
    except yaml.YAMLError as exc:
        return [], [FileError(file, "", f"bad YAML: {exc}")]
    if not isinstance(data, dict):
        return [], [FileError(file, "", "an agent config must be a YAML mapping")]
    notes: list[Note] = []
    other: list[str] = []

    def note(key: str, message: str) -> None:
        notes.append(Note(file, key, Construct.AGENT_CONFIG, message))

    local = data.get("Local")
    if isinstance(local, dict):
        for key, value in local.items():
            if key == "ID":
                note(
                    "Local.ID", f"agent id {_shown(value)}: agents are named here; give the name in --agents NAME:ROLE"
                )
            elif key == "DefaultRole":
                note("Local.DefaultRole", f"default role {_shown(value)}: give it in --agents NAME:{_shown(value)}")
            else:
                other.append(f"Local.{key}")
    alica = data.get("Alica")
    if isinstance(alica, dict):
        for key, value in alica.items():
            if key in _ALICA:
                template, _ = _ALICA[key]
                note(f"Alica.{key}", f"{key} {_shown(value)}: {_counterpart(template, value)}")
            elif key == "CycleDetection" and isinstance(value, dict):
                for sub, setting in value.items():
                    if sub in _CYCLES:
                        template, _ = _CYCLES[sub]
                        note(
                            f"Alica.CycleDetection.{sub}", f"{sub} {_shown(setting)}: {_counterpart(template, setting)}"
                        )
                    else:
                        other.append(f"Alica.CycleDetection.{sub}")
            else:
                other.append(f"Alica.{key}")
    other += [str(k) for k in data if k not in ("Local", "Alica")]
    if other:
        note("", f"settings without a counterpart, not imported: {', '.join(other)}")
    return notes, []


def other_config_note(file: str) -> Note:
    """The note on a config file of the C++ engine without a counterpart (``UdpProxy.conf``)."""
    return Note(
        file,
        "",
        Construct.OTHER_FILE,
        "a configuration of the C++ engine's transport: no counterpart; choose the transport with the options of "
        "alica run and alica agent (--processes, --listen, --connect)",
    )
