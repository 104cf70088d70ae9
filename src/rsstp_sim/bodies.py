"""The registry of bodies: one line each, the scenario table that picks it and where it lives.

A body's module is imported when a scenario first needs it, so the registry imports none of
them, and a scenario module can ask it for a parser without an import cycle.

>>> sorted(BODIES)
['arm', 'rover']
>>> body_named("rover").name
'rover'
"""

from __future__ import annotations

from importlib import import_module
from typing import TYPE_CHECKING, Any, TypeAlias

from rsstp_sim.interface import Body

if TYPE_CHECKING:
    from rsstp_sim.arm.scenario import Scenario
    from rsstp_sim.rover.scenario import RoverScenario

__all__ = ["BODIES", "AnyScenario", "body_named", "body_of", "make_world", "registered"]

BODIES: dict[str, str] = {
    "arm": "rsstp_sim.arm.world:ARM",
    "rover": "rsstp_sim.rover:ROVER",
}
"""Body name (its scenario table) -> ``module:attribute`` of its :class:`Body`."""

AnyScenario: TypeAlias = "Scenario | RoverScenario"
"""A scenario of any registered body: each body's scenario class (one name a body)."""


def registered(registry: dict[str, str], name: str) -> Any:
    """What a registry of bodies (body name -> ``module:attribute``) holds for ``name``, its
    module imported now (KeyError for none): this one, and each floor's of the replay side."""
    module, attribute = registry[name].split(":")
    return getattr(import_module(module), attribute)


def body_named(name: str) -> Body:
    """The registered body ``name`` (KeyError for none)."""
    body: Body = registered(BODIES, name)
    return body


def body_of(scenario: Any) -> Body:
    """The body a scenario describes."""
    return body_named(scenario.body)


def make_world(scenario: Any) -> Any:
    """A world of the scenario's body, at its start pose."""
    return body_of(scenario).world(scenario)
