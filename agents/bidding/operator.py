"""The operator as an action: ``bidding.operator`` creates its state with the mission
and queues it for the interface agent (REQUEST, then INFORM: the deployment, the team,
the zones and, for a random deployment, each robot's zone list)."""

from __future__ import annotations

import math
from typing import Any

from petriflow.agents.bidding.agent import Operator
from petriflow.agents.bidding.auction import random_deployment
from petriflow.agents.bidding.needs import OFFICE, office_of
from petriflow.agents.bidding.protocol import Kind, Payload
from petriflow.runtime.action import ActionContext, ActionFailure, InstantAction, Param

__all__ = ["MakeOperator"]


class MakeOperator(InstantAction):
    """The operator's mission: REQUEST, then INFORM (deployment, team, zones, lists)."""

    agent_state = Operator
    resources = OFFICE
    params = {
        "hmia": Param(str, "hmia", "the interface agent"),
        "robots": Param(list, doc="the robot agents, in rank order"),
        "deployment": Param(str, "autonomous", "autonomous (bidding) or random (the operator's lists)",
                            choices=("autonomous", "random")),
        "zones": Param((list, type(None)), None, "zone positions [[x, y], ...] in rank order (default: the"
                       " world's office)"),
        "lists": Param((list, type(None)), None, "random deployment: each robot's zone numbers (1-based), in"
                       " visiting order (default: drawn at random with the run's seed)"),
    }

    @classmethod
    def check_params(cls, given: dict[str, Any], where: str) -> dict[str, Any]:
        """The declared types, then the shapes: zones are ``[x, y]`` pairs of finite
        numbers, lists hold whole zone numbers from 1, robots are names."""
        from petriflow.errors import NetFormatError

        checked = super().check_params(given, where)

        def fail(name: str, why: str) -> None:
            error = NetFormatError(f"parameter {name!r}: {why}", element=where)
            error.param = name
            raise error

        def number(v: Any) -> bool:
            return isinstance(v, (int, float)) and not isinstance(v, bool) and math.isfinite(v)

        if not checked["robots"] or not all(isinstance(r, str) and r for r in checked["robots"]):
            fail("robots", f"a non-empty list of agent names, got {checked['robots']!r}")
        if checked["zones"] is not None and not all(
                isinstance(z, (list, tuple)) and len(z) >= 2 and all(number(v) for v in z[:2]) for z in checked["zones"]):
            fail("zones", "a list of [x, y] positions in metres")
        lists = checked["lists"]
        if lists is not None:
            if not all(isinstance(zs, list) and all(isinstance(z, int) and not isinstance(z, bool) and z >= 1
                                                    for z in zs) for zs in lists):
                fail("lists", f"one list of zone numbers (1, 2, ...) per robot, got {lists!r}")
            if len(lists) != len(checked["robots"]):
                fail("lists", f"{len(lists)} zone lists for {len(checked['robots'])} robots")
        return checked

    def run(self, ctx: ActionContext) -> None:
        p = self.params
        zones = p["zones"]
        if zones is None:
            plan = office_of(ctx)
            if plan is None:
                raise ActionFailure("bidding.operator: no zones given and the world has no meta.office")
            zones = [list(z) for z in plan.zones]
        zones = [[float(v) for v in z[:2]] for z in zones]
        robots = [str(r) for r in p["robots"]]
        if not robots:
            raise ActionFailure("bidding.operator: the team has no robot")
        lists = p["lists"]
        if p["deployment"] == "random":
            if lists is None:
                lists = random_deployment(len(robots), len(zones), ctx.rng)
            else:
                if len(lists) != len(robots):
                    raise ActionFailure(f"bidding.operator: {len(lists)} zone lists for {len(robots)} robots")
                lists = [[int(z) - 1 for z in zs] for zs in lists]
                flat = sorted(z for zs in lists for z in zs)
                if flat != list(range(len(zones))):
                    raise ActionFailure("bidding.operator: the zone lists must hold every zone number from 1 to"
                                        f" {len(zones)} once, got {[[z + 1 for z in zs] for zs in lists]}")
        mission = {"deployment": p["deployment"], "robots": robots, "zones": zones, "lists": lists}
        operator = ctx.state = Operator(ctx.agent or ctx.transition, p["hmia"], mission)
        operator.queue(p["hmia"], Payload(Kind.REQUEST, body={"task": "map"}))
        operator.queue(p["hmia"], Payload(Kind.INFORM, body={
            "deployment": p["deployment"], "zones": [tuple(z) for z in zones],
            "lists": None if lists is None else [list(zs) for zs in lists], "robots": list(robots)}))
        ctx.emit("bidding.mission", deployment=p["deployment"], robots=len(robots), zones=len(zones),
                 lists=None if lists is None else [[z + 1 for z in zs] for zs in lists])

