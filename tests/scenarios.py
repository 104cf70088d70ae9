"""TOML text for tests and benches: a scenario from a plain dict or from an arm and its
obstacles in one call, and the sweep most sweep tests start from.

The benches that build scenarios import it too (they put this folder on the path), so it needs
nothing but the standard library.
"""

from __future__ import annotations

import json
from collections.abc import Mapping, Sequence

Disk = tuple[tuple[float, float], float]
"""An obstacle: its center (x, y) and its radius."""


def _toml_value(value: object) -> str:
    if isinstance(value, bool):
        return "true" if value else "false"
    if isinstance(value, int | float):
        return repr(value)  # nan and inf are valid TOML floats
    if isinstance(value, str):
        return json.dumps(value)
    if isinstance(value, list | tuple):
        return "[" + ", ".join(_toml_value(v) for v in value) + "]"
    if isinstance(value, Mapping):  # an inline table
        return "{" + ", ".join(f"{k} = {_toml_value(v)}" for k, v in value.items()) + "}"
    raise TypeError(f"no TOML form for {value!r}")


def toml_text(data: Mapping[str, object]) -> str:
    """TOML for ``data``: top-level values, then ``[tables]`` and ``[[arrays of tables]]``."""
    lines: list[str] = []
    tables: list[tuple[str, Mapping[str, object]]] = []
    for key, value in data.items():
        if isinstance(value, Mapping):
            tables.append((f"[{key}]", value))
        elif isinstance(value, list) and value and all(isinstance(v, Mapping) for v in value):
            tables.extend((f"[[{key}]]", v) for v in value)
        else:
            lines.append(f"{key} = {_toml_value(value)}")
    for header, table in tables:
        lines += ["", header, *(f"{k} = {_toml_value(v)}" for k, v in table.items())]
    return "\n".join(lines) + "\n"


def arm_toml(
    lengths: Sequence[float],
    initial_deg: Sequence[int],
    step_deg: int,
    obstacles: Sequence[Disk] = (),
    *,
    name: str | None = None,
    actions: Sequence[int] | None = None,
    **tables: Mapping[str, object],
) -> str:
    """A scenario's TOML: ``name``, the ``[arm]`` (link ``lengths``, ``initial_deg``,
    ``step_deg``, and ``actions`` when given), one ``[[obstacles]]`` per (center, radius) disk,
    then each of ``tables`` (``feedback``, ``motion``...) as a ``[table]``."""
    arm: dict[str, object] = {
        "lengths": list(lengths),
        "initial_deg": list(initial_deg),
        "step_deg": step_deg,
    }
    if actions is not None:
        arm["actions"] = list(actions)
    data: dict[str, object] = {} if name is None else {"name": name}
    data["arm"] = arm
    if obstacles:
        data["obstacles"] = [{"center": list(center), "radius": r} for center, r in obstacles]
    return toml_text({**data, **tables})


def sweep_toml(*, steps: int, seeds: int, more_strategies: Sequence[str] = ()) -> str:
    """A sweep of ``thesis-roulette`` and ``one-joint-10`` by the learner and a script of
    action 0 (``params = { actions = [0] }``), then one ``[[strategy]]`` for each name of
    ``more_strategies``."""
    text = f"""
steps = {steps}
seeds = {seeds}
scenarios = ["thesis-roulette", "one-joint-10"]
[[strategy]]
name = "learner"
[[strategy]]
name = "script"
params = {{ actions = [0] }}
"""
    return text + "".join(f'[[strategy]]\nname = "{name}"\n' for name in more_strategies)
