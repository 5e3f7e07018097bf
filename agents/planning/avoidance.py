"""Collision detection and priority-based avoidance between robots (seed 003 §4.2).

After every move the robots' distances are measured. Two robots closer than two
standard steps are *in conflict*: both stop; the one of higher priority plans again,
treating the other as a fixed obstacle, and goes on along its new path; the one of
lower priority holds until the other has passed the critical region, then resumes its
own path. Priorities come with the cooperative task.

Distances here are gaps between the robots' discs (centre distance minus both radii;
with radii 0, centre distances as the paper measures them). Two steps of gap leave
each robot one full move before contact. A pair with different step lengths uses the
sum of one step of each.

:class:`CollisionAvoidance` keeps the state (who holds for whom) and turns positions
into one :class:`Directive` per robot each time it is updated.

Examples:
    >>> avoid = CollisionAvoidance({"red": 2, "blue": 1}, step=0.05)
    >>> avoid.update({"red": (0.0, 0.0), "blue": (1.0, 0.0)})["red"].order.value
    'go'
    >>> orders = avoid.update({"red": (0.0, 0.0), "blue": (0.08, 0.0)})
    >>> orders["red"]
    Directive(order=<Order.REPLAN: 'replan'>, others=('blue',))
    >>> orders["blue"]
    Directive(order=<Order.HOLD: 'hold'>, others=('red',))
    >>> avoid.update({"red": (0.0, -0.05), "blue": (0.08, 0.0)})["blue"].order.value
    'hold'
    >>> avoid.update({"red": (-0.1, -0.1), "blue": (0.08, 0.0)})["blue"].order.value
    'go'
"""

from __future__ import annotations

import enum
import math
from dataclasses import dataclass, field
from typing import Mapping, Sequence

from petriflow.agents.planning.errors import PlanningError

__all__ = ["Order", "Directive", "gap", "conflicts", "CollisionAvoidance"]


class Order(str, enum.Enum):
    """What a robot is told after a move."""

    GO = "go"
    """Carry on along the current path."""
    REPLAN = "replan"
    """Stop, plan again with the robots in ``others`` as fixed obstacles, then go."""
    HOLD = "hold"
    """Stay where you are until the robots in ``others`` have passed."""


@dataclass(frozen=True)
class Directive:
    """One robot's order and the robots it concerns."""

    order: Order
    others: tuple[str, ...] = ()


def _per_robot(value: float | Mapping[str, float], name: str, what: str) -> float:
    if isinstance(value, Mapping):
        if name not in value:
            raise PlanningError(f"no {what} given for robot {name!r}")
        return float(value[name])
    return float(value)


def gap(a: Sequence[float], b: Sequence[float], radius_a: float = 0.0, radius_b: float = 0.0) -> float:
    """Free distance between two disc robots at ``a`` and ``b`` (negative: overlapping).

    Examples:
        >>> gap((0, 0), (0.3, 0.4)), gap((0, 0), (0.3, 0.4), 0.1, 0.15)
        (0.5, 0.25)
    """
    return math.hypot(a[0] - b[0], a[1] - b[1]) - radius_a - radius_b


def conflicts(positions: Mapping[str, Sequence[float]], step: float | Mapping[str, float],
              radius: float | Mapping[str, float] = 0.0, steps: float = 2.0) -> list[tuple[str, str, float]]:
    """Pairs of robots closer than ``steps`` standard steps, as ``(a, b, gap)`` with
    ``a < b`` by name, sorted.

    Examples:
        >>> conflicts({"a": (0, 0), "b": (0.09, 0), "c": (1, 0)}, step=0.05)
        [('a', 'b', 0.09)]
    """
    names = sorted(positions)
    found = []
    for i, a in enumerate(names):
        for b in names[i + 1:]:
            limit = steps / 2.0 * (_per_robot(step, a, "step") + _per_robot(step, b, "step"))
            apart = gap(positions[a], positions[b], _per_robot(radius, a, "radius"),
                        _per_robot(radius, b, "radius"))
            if apart < limit:
                found.append((a, b, apart))
    return found


@dataclass
class _Encounter:
    leader: str
    follower: str
    gap: float


@dataclass
class CollisionAvoidance:
    """Priority-based collision avoidance for a team of robots.

    Args:
        priorities: ``{robot: priority}``, higher goes first (equal priorities: the
            name that sorts first).
        step: standard step length (m), one for all or per robot.
        radius: robot radius (m), one for all or per robot; 0 measures centre
            distances.
        steps: how many standard steps of gap make a conflict (the paper: two).

    A held robot is released once the leader has *passed*: their gap is at least the
    conflict distance again and grew since the last update, or the leader is no longer
    among the positions given (it arrived or left the task). A robot that should
    re-plan while it is itself held re-plans as soon as it is released.
    """

    priorities: Mapping[str, float]
    step: float | Mapping[str, float]
    radius: float | Mapping[str, float] = 0.0
    steps: float = 2.0
    encounters: list[_Encounter] = field(default_factory=list)
    _pending: dict[str, set[str]] = field(default_factory=dict, repr=False)

    def _rank(self, name: str) -> tuple[float, str]:
        if name not in self.priorities:
            raise PlanningError(f"robot {name!r} has no priority")
        return (-float(self.priorities[name]), name)

    def _limit(self, a: str, b: str) -> float:
        return self.steps / 2.0 * (_per_robot(self.step, a, "step") + _per_robot(self.step, b, "step"))

    def held(self) -> dict[str, tuple[str, ...]]:
        """``{robot: leaders it waits for}`` for every robot currently held."""
        waiting: dict[str, list[str]] = {}
        for encounter in self.encounters:
            waiting.setdefault(encounter.follower, []).append(encounter.leader)
        return {name: tuple(sorted(leaders)) for name, leaders in sorted(waiting.items())}

    def update(self, positions: Mapping[str, Sequence[float]]) -> dict[str, Directive]:
        """Directives for every robot in ``positions`` after a move.

        Returns:
            ``{robot: Directive}``: ``REPLAN`` for a leader of a new conflict (with the
            robots to treat as obstacles), ``HOLD`` for a robot waiting (with the
            robots it waits for), ``GO`` otherwise.
        """
        # 1. end the encounters whose leader has passed (or whose robots are gone)
        still: list[_Encounter] = []
        for encounter in self.encounters:
            if encounter.leader not in positions or encounter.follower not in positions:
                continue
            now = gap(positions[encounter.leader], positions[encounter.follower],
                      _per_robot(self.radius, encounter.leader, "radius"),
                      _per_robot(self.radius, encounter.follower, "radius"))
            if now >= self._limit(encounter.leader, encounter.follower) and now > encounter.gap:
                continue
            encounter.gap = now
            still.append(encounter)
        self.encounters = still
        engaged = {pair for e in self.encounters for pair in ((e.leader, e.follower), (e.follower, e.leader))}
        # 2. new conflicts: the higher-priority robot re-plans, the other holds
        for a, b, apart in conflicts(positions, self.step, self.radius, self.steps):
            if (a, b) in engaged:
                continue
            leader, follower = sorted((a, b), key=self._rank)
            self.encounters.append(_Encounter(leader, follower, apart))
            self._pending.setdefault(leader, set()).add(follower)
        # 3. orders: holding wins; a pending re-plan waits until its robot is free
        waiting = self.held()
        orders: dict[str, Directive] = {}
        for name in sorted(positions):
            if name in waiting:
                orders[name] = Directive(Order.HOLD, waiting[name])
            elif name in self._pending:
                obstacles = {f for f in self._pending.pop(name) if f in positions}
                orders[name] = Directive(Order.REPLAN, tuple(sorted(obstacles)))
            else:
                orders[name] = Directive(Order.GO)
        for name in list(self._pending):
            if name not in positions:
                del self._pending[name]
        return orders
