"""Writing the chosen gait design into a copy of the settings file, every value commented.

The file's own lines are kept (and its comments, but on the lines changed): the servo
gain, gait frequency, physics rate and each oscillator's range are replaced where they
stand, each with a comment naming the search; a relative ``urdf`` is rewritten relative
to the new file's folder; a ``design_search:`` record (replacing any earlier one) says
how the values were found and what they replaced. The text is read back and must give
exactly the chosen design, or nothing is written.
"""

from __future__ import annotations

import os
import re
from pathlib import Path

import yaml

from evorbc_ros.config import ConfigError
from offline_evolution.gait_design.space import DesignSpace
from sim_bridge.legged.settings import PYBULLET_DATA, robot_settings_from_mapping

_TOP = re.compile(r"^([A-Za-z_][\w]*)\s*:")


def _in_section(lines: list[str], section: str):
    """``(index, line)`` of the lines inside top-level mapping ``section``."""
    current = None
    for i, line in enumerate(lines):
        top = _TOP.match(line)
        if top:
            current = top.group(1)
        elif current == section:
            yield i, line


def _replace_scalar(lines: list[str], section: str, name: str, value: str, note: str) -> None:
    """Replace ``section: {name: ...}`` written as an indented block line."""
    for i, line in _in_section(lines, section):
        m = re.match(rf"^(\s+){re.escape(name)}\s*:\s*([^#\s]+)", line)
        if m:
            lines[i] = f"{m.group(1)}{name}: {value}  # {note} (was {m.group(2)})"
            return
    raise ConfigError(f"no line '{name}:' in the {section} section")


def _replace_range(lines: list[str], oscillator: str, pair: list[float], note: str) -> None:
    """Replace the range of oscillator ``oscillator`` (flow or block style)."""
    pattern = re.compile(r"\brange(_deg)?\s*:\s*\[[^\]]*\]")
    for i, line in _in_section(lines, "oscillators"):
        m = re.match(rf"^(\s+){re.escape(oscillator)}\s*:", line)
        if not m:
            continue
        for k in range(i, len(lines)):
            below = lines[k]
            if k > i and below.strip() and len(below) - len(below.lstrip()) <= len(m.group(1)):
                break
            found = pattern.search(below.split("#", 1)[0])
            if found:
                body = below.split("#", 1)[0].rstrip()
                body = pattern.sub(f"range_deg: [{pair[0]:g}, {pair[1]:g}]", body, count=1)
                was = found.group(0).split(":", 1)[1].strip()
                lines[k] = f"{body}  # {note} (was {was})"
                return
    raise ConfigError(f"no range of oscillator {oscillator!r} in the oscillators section")


def _drop_record(lines: list[str]) -> list[str]:
    out, skipping = [], False
    for line in lines:
        top = _TOP.match(line)
        if top:
            skipping = top.group(1) == "design_search"
        if not skipping:
            out.append(line)
    while out and not out[-1].strip():
        out.pop()
    return out


def _urdf_line(lines: list[str], data: dict, source: Path, out: Path) -> None:
    value = str(data["urdf"])
    if value.startswith(PYBULLET_DATA) or Path(value).is_absolute():
        return
    target = (source.parent / value).resolve()
    moved = os.path.relpath(target, out.resolve().parent)
    if moved == value:
        return
    for i, line in enumerate(lines):
        if re.match(r"^urdf\s*:", line):
            lines[i] = f"urdf: {moved}  # {value} beside {source.name}, from this file's folder"
            return


def design_text(
    text: str, space: DesignSpace, values: dict, record: dict, source: Path, out: Path
) -> str:
    """The settings file's ``text`` with ``values`` chosen and ``record`` appended.

    Raises:
        ConfigError: a value could not be placed (the file's layout), or the text read
            back is not the chosen design.

    """
    note = f"design-gait, seed {record['seed']}, {record['budget']} budget"
    lines = _drop_record(text.splitlines())
    try:
        _replace_scalar(lines, "servo", "gain", f"{values['gain']:g}", f"1/s, {note}")
        _replace_scalar(lines, "gait", "frequency_hz", f"{values['frequency_hz']:g}", f"Hz, {note}")
        _replace_scalar(lines, "physics", "rate_hz", f"{values['rate_hz']:g}", f"Hz, {note}")
        for name, pair in space.ranges_deg(values).items():
            _replace_range(lines, name, pair, f"deg, {note}")
    except ConfigError as e:
        problem = f"{source}: cannot write the design into this file's layout ({e})"
        raise ConfigError(problem) from None
    _urdf_line(lines, space.data, source, out)
    lines += [
        "# How the gait design above was found: evorbc-evolve design-gait (docs/legged.md,",
        '# "The gait design search"); score and measures are the chosen design\'s on fresh',
        "# primitives (validation), 'replaced' the file's design before the search.",
        *yaml.safe_dump(
            {"design_search": record}, sort_keys=False, default_flow_style=None, width=100
        ).splitlines(),
    ]
    new = "\n".join(lines) + "\n"
    got = robot_settings_from_mapping(yaml.safe_load(new), out).describe()
    want = space.design(values).describe()
    if got != want:
        raise ConfigError(f"{source}: the design written into {out} reads back differently")
    return new
