"""The built-in scenarios of one body, for tests that exercise a body's own parts."""

from __future__ import annotations

from rsstp_sim.scenario import builtin_scenarios, load_scenario


def builtins_of(body: str) -> list[str]:
    """The names of the built-in scenarios whose body is ``body``, sorted."""
    return [name for name in sorted(builtin_scenarios()) if load_scenario(name).body == body]
