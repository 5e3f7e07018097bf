"""The framework's processes and the mapping task as actions nets bind by name.

Start-up, in order (seed 000 §3.2), each a transition of every agent's subnet:

* ``comm.characterise`` (process 1): the robot's wheels and encoders give ``dpp``
  (eq. 2); its start on the odometry grid ``pg`` (eq. 3) is reported. Makes the
  agent's state (:class:`~petriflow.agents.comm.agent.CommAgent`, ``ctx.state``), which
  the run keeps and every later action and guard of the agent reads (the subnet
  declares ``state: comm.agent``); tokens carry no data.
* ``comm.analyse`` (process 2): the Fig. 5 sweep on the radio model of one of its
  channel places: the distance up to which nothing is lost behind a wall, and the RSSI
  threshold it will use.
* ``comm.initialise`` (process 3): its address by eq. 4 (or, for a late joiner, the
  first free address of a peer's DHCP pool, eq. 5).
* ``comm.history`` (process 4): empty ``Ad`` and ``Ah``; marks the agent's work loop
  and its listening place.

Then the task, as a loop per agent: ``comm.explore`` (a robot moves to the next cell,
senses its walls with four distance rays, adds a vertex, and plans what to send with
Algorithm 1 for each peer it hears above the threshold) or ``comm.listen`` (a static
agent: a monitor or the central unit, waits ``period`` s and plans); ``comm.send`` puts
one waiting message into the channel place towards a peer (process 5: a token sized in
bytes); ``comm.receive`` takes one from a channel place into the agent's history.
Guards route the loop: ``comm.has_message`` (for the transition's ``peer``; it reads
the state key ``outbox/{peer}``, so it is asked again only when that peer's queue or
hearing changed), ``comm.going_on`` and ``comm.finished`` (they read the whole state,
``*``: asked again after each firing of the agent).

Whether a peer runs (what its radio beacon tells) comes from the run's
``core.liveness`` resource; every place an action names is a declared parameter
(``Param(..., places=...)``), the peers' boxes inside ``comm.initialise``'s mapping
included, so a misspelt place fails when the net is loaded, naming its file and line.
"""

from __future__ import annotations

import math
from typing import Any

from petriflow.agents.comm.agent import CommAgent, Peer, vertex_id
from petriflow.agents.comm.framework import History, addresses, dhcp_pools, dpp, grid_position, grid_size
from petriflow.agents.comm.radio import RadioChannel, pick_threshold, threshold_sweep
from petriflow.agents.mobile.maze import MAZE

from petriflow.capabilities import Bodies, Physics, Positions, provides
from petriflow.runtime.action import Action, ActionContext, ActionFailure, InstantAction, Param, Status
from petriflow.runtime.resources import LIVENESS, Liveness

__all__ = [
    "GUARDS",
    "Analyse",
    "Characterise",
    "Explore",
    "Initialise",
    "Listen",
    "MakeHistory",
    "Receive",
    "Send",
]


class Characterise(InstantAction):
    """Process 1: make the agent's state; a robot's dpp (eq. 2) and start on the grid (eq. 3)."""

    agent_state = CommAgent
    settings = MAZE  # the maze the metrics score the maps against, checked when the world loads

    params = {
        "kind": Param(str, "robot", "robot, monitor or central", choices=("robot", "monitor", "central")),
        "wheel_radius": Param(float, 0.025, "wheel radius r (m)", low=1e-9),
        "ppr": Param(int, 200, "encoder pulses per wheel revolution", low=1),
        "track": Param(float, 0.2, "distance between the wheels (m)", low=1e-9),
        "area": Param(list, [5.0, 5.0], "the environment's size D = [Dx, Dy] (m)"),
        "cell": Param(float, 0.5, "the maze's cell size (m): where the robot stops to sense", low=1e-9),
        "cols": Param(int, 10, "cells per maze row (a vertex id is row * cols + col)", low=1),
        "origin": Param(list, [0.0, 0.0], "world (x, y) of the maze's south-west corner"),
    }

    @classmethod
    def requirements(cls, params: dict[str, Any]) -> frozenset[str]:
        return frozenset({"world"}) if params["kind"] == "robot" else frozenset()

    def run(self, ctx: ActionContext) -> None:
        p = self.params
        agent = ctx.agent or ctx.transition
        state = CommAgent(agent, p["kind"], cell=p["cell"], origin=tuple(p["origin"]), cols=p["cols"],
                          cells=p["cols"] * max(1, round(p["area"][1] / p["cell"])))
        report: dict[str, Any] = {"agent": agent, "role": p["kind"]}
        if p["kind"] == "robot":
            if ctx.world is None:
                raise ActionFailure("comm.characterise: a robot needs a world")
            from petriflow.agents.mobile.explore import Explorer
            from petriflow.agents.mobile.kinematic import KinematicRobot

            step = dpp(p["wheel_radius"], p["ppr"])
            state.robot = KinematicRobot(ctx.world, agent, radius=p["wheel_radius"], ppr=p["ppr"], track=p["track"])
            x, y, _ = state.robot.pose
            state.explorer = Explorer(self._cell(state, x, y))
            report.update(dpp_mm=round(step * 1000, 4), grid=list(grid_size(tuple(p["area"]), [step])),
                          pg=list(grid_position((x - state.origin[0], y - state.origin[1]), step)))
        ctx.emit("comm.characterised", **report)
        ctx.state = state

    @staticmethod
    def _cell(state: CommAgent, x: float, y: float) -> tuple[int, int]:
        return (int((y - state.origin[1]) // state.cell), int((x - state.origin[0]) // state.cell))


class Analyse(InstantAction):
    """Process 2: sweep the link of a channel place behind a wall (Fig. 5); keep the threshold."""

    params = {
        "channel_place": Param(str, doc="a channel place of this agent whose radio to analyse", places=""),
        "distances": Param(int, 10, "distances 1..N m", low=1),
        "trials": Param(int, 100, "frames per distance", low=1),
    }

    def run(self, ctx: ActionContext) -> None:
        model, _ = ctx.link(self.params["channel_place"])
        if isinstance(model, RadioChannel):
            rows = threshold_sweep(model, range(1, self.params["distances"] + 1), walls=1,
                                   trials=self.params["trials"], seed=ctx.seed)
            distance, level = pick_threshold(rows)
            ctx.emit("comm.analysed", lossless_behind_wall_m=distance, rssi_there_dbm=level,
                     threshold_dbm=model.threshold_dbm, range_m=round(model.range(), 3))


class Initialise(InstantAction):
    """Process 3: the agent's address (eq. 4), or one from a peer's DHCP pool (eq. 5)."""

    agent_state = CommAgent

    params = {
        "index": Param(int, 0, "this agent's index i among the initial agents", low=0),
        "agents": Param(int, 1, "N, the initial agents (the robots)", low=1),
        "available": Param(int, 253, "A, the addresses available", low=2),
        "pool_of": Param((int, type(None)), None, "a late joiner: take the first free address of agent i's pool"),
        "address": Param((int, type(None)), None, "a fixed address instead (the central unit)"),
        "peers": Param(dict, {}, "peer agent -> {address: A, box: channel place towards it}", places="*.box"),
    }

    def run(self, ctx: ActionContext) -> None:
        state = ctx.state
        p = self.params
        team = addresses(p["agents"], p["available"])
        if p["address"] is not None:
            state.address = p["address"]
        elif p["pool_of"] is not None:
            state.address = dhcp_pools(p["agents"], p["available"])[p["pool_of"]][0]
        else:
            if not 0 <= p["index"] < p["agents"]:
                raise ActionFailure(f"comm.initialise: index {p['index']} is not one of {p['agents']} agents")
            state.address = team[p["index"]]
        state.team = set(team)
        for name, peer in p["peers"].items():
            state.peers[name] = Peer(name, int(peer["address"]), str(peer["box"]))
        ctx.emit("comm.initialised", address=f"192.168.1.{state.address}")


class MakeHistory(InstantAction):
    """Process 4: the empty data and history arrays. The central unit keeps its
    history per recipient by vertex: a vertex a robot holds, whoever mapped it, is not
    forwarded to it (``History(identity=vertex_id)``); a robot's history is the
    paper's, per source."""

    agent_state = CommAgent

    def run(self, ctx: ActionContext) -> None:
        state = ctx.state
        state.history = History(state.address, identity=vertex_id if state.kind == "central" else None)
        state.last_news = state.since = ctx.now  # a late joiner waits for news from when it joined


def _plan(ctx: ActionContext, state: CommAgent, links: dict[str, Any]) -> None:
    """Algorithm 1 towards every peer heard above the threshold now.

    ``links`` keeps, per channel place, the model carrying it (the same for the whole
    run); the agents' positions are read once per plan (nothing moves during it)."""
    state.now = ctx.now
    live: Liveness = ctx.resource("live")
    peers = [peer for peer in state.peers.values() if live.alive(peer.name)]  # the others: no beacon
    world = ctx.world
    positions = None
    if peers and provides(world, Positions):  # a static agent may run without a world
        positions = {state.name: world.position(state.name)}
        positions.update((peer.name, world.position(peer.name)) for peer in peers)
    heard = set()
    for peer in peers:
        model = links.get(peer.box)
        if model is None:
            model = links[peer.box] = ctx.link(peer.box)[0]
        usable = model.usable(state.name, peer.name, positions) if isinstance(model, RadioChannel) else True
        if usable:
            heard.add(peer.name)
            for message in state.resend(peer.name):  # TCP gets what the radio lost through first
                _take_in(ctx, state, message, resent=True)
            state.plan_for(peer)
    state.hear(heard)


def _take_in(ctx: ActionContext, state: CommAgent, message: Any, resent: bool = False) -> None:
    """One message that reached this agent: into its history and map (``resent``: one
    the radio had lost, now through)."""
    if resent:
        sender = state.by_address(message.sender)
        ctx.emit("comm.resent", sender=sender.name if sender is not None else str(message.sender),
                 code=message.code, source=message.source)
    new = state.receive(message)
    sender = state.by_address(message.sender)
    if sender is not None:
        state.met(sender.name)  # within range here: a place to meet again
    if new or message.final:
        state.last_news = ctx.now
    if new:
        if state.explorer is not None:
            state.explorer.learn((v // state.cols, v % state.cols) for v in new)
        ctx.emit("comm.learnt", ids=new)


class Explore(Action):
    """A robot goes to its next cell, senses its walls, maps a vertex, plans what to send.

    After its own exploration a decentralised robot (``meet``) heads for a robot whose
    data it lacks or that it has still to tell: back to the cell where it last talked
    with it, else to the border of its region (a rendezvous), and waits there, choosing
    again when whom it waits for changes; a robot whose header says it cannot move is
    not visited. One that has waited ``give_up`` s re-explores what the silent robots
    had claimed. A centralised robot waits for the central unit's relay. At ``stop_at``
    the robot breaks down: it stops for good, its data is final, its radio goes on.
    """

    params = {
        "speed": Param(float, 0.15, "cruise speed (m/s)", low=1e-9),
        "turn_rate": Param(float, 1.5, "turn rate on the spot (rad/s)", low=1e-9),
        "sensor_z": Param(float, 0.1, "height of the distance sensors (m)"),
        "give_up": Param(float, 240.0, "seconds after its exploration to wait for silent robots", low=0),
        "reexplore": Param(bool, True, "re-explore silent robots' cells after give_up (decentralised)"),
        "wait": Param(float, 1.0, "seconds between plans while waiting", low=1e-9),
        "jitter": Param(float, 0.1, "each move's speed is the cruise speed times U(1 - j, 1 + j) (seeded)",
                         low=0, high=1),
        "stop_at": Param((float, int, type(None)), None, "a mechanical failure at this time: the robot stops"
                         " moving for good, its data is final as it stands, its radio goes on"),
        "meet": Param(bool, True, "after exploring, drive to meet robots whose data is missing (decentralised;"
                      " a centralised robot waits for the central unit's relay)"),
    }
    needs_world = True
    agent_state = CommAgent
    resources = {"live": LIVENESS}
    uses = (Physics, Bodies, Positions)

    def setup(self, world: Any) -> None:
        self.links: dict[str, Any] = {}  # channel place -> the model carrying it (see _plan)

    def start(self, ctx: ActionContext) -> None:
        self.state = state = ctx.state
        state.now = ctx.now
        state.patience = self.params["give_up"]
        if state.robot is None:
            raise ActionFailure("comm.explore: the agent has no robot (use comm.listen for static agents)")
        self.needs_world = True  # polled at every world step while it drives
        self.wake_at = None
        self.goal = None
        self.waiting = 0.0
        self.at = ctx.now
        self._start(ctx)
        if self.goal is None:
            self._sleep(ctx)

    def _start(self, ctx: ActionContext) -> None:
        state = self.state
        jitter = min(max(self.params["jitter"], 0.0), 0.9)
        self.speed = self.params["speed"] * (1.0 + jitter * (2.0 * ctx.rng.random() - 1.0))
        explorer = state.explorer
        stop_at = self.params["stop_at"]
        if stop_at is not None and ctx.now >= stop_at:
            if not state.broken:
                state.broken = True
                ctx.emit("comm.broken", distance_m=round(state.robot.travelled, 3))
                if not state.explored:
                    self._explored(ctx)  # it will explore no more: what it has is all of its data
            self._give_up(ctx, state.missing())
            self.waiting = self.params["wait"]
            return
        if not state.explored:
            if not explorer.visited:
                self.goal = explorer.cell
            else:
                self.goal = explorer.next_cell()
                if self.goal is None:
                    self._explored(ctx)
        if state.explored:
            self._route(ctx)

    def _sleep(self, ctx: ActionContext) -> None:
        """A robot that waits is woken once, at the world step where counting its wait
        down step by step (as :meth:`poll` would) reaches zero, instead of being polled
        at every step: the same step, the same remainder, for a fraction of the cost."""
        step = ctx.world.dt
        if not step:
            return
        tick = round(ctx.now / step)
        at, left = ctx.now, self.waiting
        while True:
            tick += 1
            now = tick * step
            left -= now - at
            at = now
            if left <= 0:
                break
        self.needs_world = False
        self.wake_at = now
        self.waiting = left

    def _explored(self, ctx: ActionContext) -> None:
        state = self.state
        state.explored = True
        state.explored_at = ctx.now
        state.final[state.address] = len(state.history.items(state.address))
        ctx.emit("comm.explored", vertices=state.final[state.address], distance_m=round(state.robot.travelled, 3))

    def _route(self, ctx: ActionContext) -> None:
        """After exploring: go towards a robot whose data is missing, else wait."""
        state = self.state
        missing = state.missing()
        if missing and ctx.now - max(state.explored_at or 0.0, state.last_news) > self.params["give_up"]:
            if self.params["reexplore"] and not state.reexplored:
                state.reexplored = True
                cells = {(v // state.cols, v % state.cols) for s in missing for v in
                         [item[0] for item in state.history.items(s)]}
                state.explorer.known -= cells
                state.explorer.stack = []
                state.explored = False
                state.parked = False
                state.route = []
                del state.final[state.address]
                self.goal = state.explorer.next_cell()
                ctx.emit("comm.reexplore", silent=sorted(missing), cells=len(cells))
                return
            self._give_up(ctx, missing)
        waiting_for = [s for s in missing if s not in state.gave_up]
        if not self.params["meet"]:
            self.goal = None
            self.waiting = self.params["wait"]
            return
        stopped = {state.peers[name].address for name in state.stopped if name in state.peers}
        waiting_for = [s for s in waiting_for if s not in stopped]
        owed = state.untold() + [name for name, box in state.outbox.items() if box and name not in state.stopped]
        waiting_for += [state.peers[name].address for name in owed if state.peers[name].address not in waiting_for]
        if state.parked and tuple(waiting_for) != state.parked_for:
            state.parked = False  # someone else to meet now (or no longer): choose the place again
        if waiting_for and not state.route and not state.parked:
            state.route = self._meeting_route(waiting_for)
            state.parked = not state.route
            state.parked_for = tuple(waiting_for)
        if state.route:
            self.goal = state.route.pop(0)
        else:
            self.goal = None
            self.waiting = self.params["wait"]

    def _give_up(self, ctx: ActionContext, missing: list[int]) -> None:
        """Give up on the robots whose data is missing, after ``give_up`` s without news."""
        state = self.state
        if missing and ctx.now - max(state.explored_at or 0.0, state.last_news) > self.params["give_up"] \
                and not state.gave_up >= set(missing):
            state.gave_up |= set(missing)
            ctx.emit("comm.gave_up", silent=sorted(missing))

    def _meeting_route(self, sources: list[int]) -> list[tuple[int, int]]:
        """Cells to a place to meet a robot whose data is missing (or that is still to be
        told): the cell where this robot last heard it (they were in range there; both
        go back to it), else the nearest visited cell with an open side into a cell that
        robot mapped (the border between the two explored regions), else the visited
        cell nearest where it was last heard of."""
        import networkx as nx

        state = self.state
        explorer = state.explorer
        graph = self._graph()
        here = explorer.cell
        if here not in graph:
            return []
        for source in sources:
            peer = state.by_address(source)
            met = state.met_at.get(peer.name) if peer is not None else None
            if met is not None and met in graph and nx.has_path(graph, here, met):
                return nx.shortest_path(graph, here, met)[1:]  # empty when here: it waits here
        lengths = nx.single_source_shortest_path_length(graph, here)
        offsets = {"north": (1, 0), "south": (-1, 0), "east": (0, 1), "west": (0, -1)}
        for source in sources:
            theirs = {(item[0] // state.cols, item[0] % state.cols) for item in state.history.items(source)}
            border = [cell for cell in lengths if any(
                (cell[0] + offsets[side][0], cell[1] + offsets[side][1]) in theirs
                for side in explorer.open.get(cell, []))]
            if border:
                goal = min(border, key=lambda c: (lengths[c], c))
                return nx.shortest_path(graph, here, goal)[1:]
        for source in sources:
            if source in state.last_seen:
                return self._path_to(state.last_seen[source])
        return []

    def _graph(self):
        import networkx as nx

        explorer = self.state.explorer
        graph = nx.Graph()
        graph.add_node(explorer.cell)
        offsets = {"north": (1, 0), "south": (-1, 0), "east": (0, 1), "west": (0, -1)}
        for cell, sides in explorer.open.items():
            graph.add_node(cell)
            for side in sides:
                other = (cell[0] + offsets[side][0], cell[1] + offsets[side][1])
                if other in explorer.visited:
                    graph.add_edge(cell, other)
        return graph

    def _path_to(self, target: tuple[float, float]) -> list[tuple[int, int]]:
        """Cells from here to the visited cell nearest ``target``, through visited cells."""
        import networkx as nx

        state = self.state
        explorer = state.explorer
        graph = nx.Graph()
        offsets = {"north": (1, 0), "south": (-1, 0), "east": (0, 1), "west": (0, -1)}
        for cell, sides in explorer.open.items():
            for side in sides:
                other = (cell[0] + offsets[side][0], cell[1] + offsets[side][1])
                if other in explorer.visited:
                    graph.add_edge(cell, other)
        here = explorer.cell
        if here not in graph:
            return []
        centre = lambda c: (state.origin[0] + (c[1] + 0.5) * state.cell, state.origin[1] + (c[0] + 0.5) * state.cell)
        nearest = min(graph.nodes, key=lambda c: math.dist(centre(c), target))
        if nearest == here:
            return []
        return nx.shortest_path(graph, here, nearest)[1:]

    def poll(self, ctx: ActionContext) -> Status:
        state = self.state
        if not self.needs_world:  # woken when its wait is over (see _sleep)
            if ctx.now < self.wake_at - 1e-9:
                return Status.RUNNING
            self.at = ctx.now
            state.robot.drive(0.0, 0.0, 0.0)  # a robot at rest holds its place (braked: not pushed away)
            _plan(ctx, state, self.links)
            return Status.OK
        robot = state.robot
        dt = ctx.now - self.at  # the first poll comes at the start: no time has passed yet
        if dt <= 1e-12:
            return Status.RUNNING
        self.at = ctx.now
        if self.goal is None:
            self.waiting -= dt
            if self.waiting > 0:
                return Status.RUNNING
            state.robot.drive(0.0, 0.0, 0.0)  # a robot at rest holds its place (braked: not pushed away)
            _plan(ctx, state, self.links)
            return Status.OK
        cell = self.goal
        target = (state.origin[0] + (cell[1] + 0.5) * state.cell, state.origin[1] + (cell[0] + 0.5) * state.cell)
        if not robot.step_towards(target, self.speed, self.params["turn_rate"], dt):
            return Status.RUNNING
        self._sense(ctx, cell)
        ctx.emit("comm.step", cell=list(cell), distance_m=round(robot.travelled, 3))
        if state.explorer.stack and state.explorer.stack[-1] != cell and not state.explored:
            state.explorer.stack.append(cell)  # arrived by a route, not by the explorer
        _plan(ctx, state, self.links)
        return Status.OK

    def _sense(self, ctx: ActionContext, cell: tuple[int, int]) -> None:
        from petriflow.agents.mobile.sensors import cast

        state = self.state
        world = ctx.world
        x, y, _ = state.robot.pose
        robots = [world.body(name) for name in world.agents]
        angles = [math.pi / 2, -math.pi / 2, 0.0, math.pi]  # north, south, east, west (world frame)
        ranges = cast(world, (x, y), 0.0, angles, state.cell, z=self.params["sensor_z"], ignore=robots)
        sides = [side for side, reach in zip(("north", "south", "east", "west"), ranges) if reach > 0.75 * state.cell]
        state.explorer.sense(cell, sides)
        if state.explorer.is_vertex(cell):
            ox, oy, _ = state.robot.odometry
            vertex_id = cell[0] * state.cols + cell[1]
            vertex = (vertex_id, round(ox, 2), round(oy, 2))
            if vertex_id not in state.vertices and state.history.add_own(vertex):
                ctx.emit("comm.learnt", ids=[vertex_id], distance_m=round(state.robot.travelled, 3))


class Listen(InstantAction):
    """A static agent (monitor, central unit): wait ``period`` s, then plan what to send."""

    params = {"period": Param(float, 1.0, "seconds between plans", low=1e-9),
              "give_up": Param(float, 240.0, "seconds without news after which missing robots are given up",
                                 low=0)}
    agent_state = CommAgent
    resources = {"live": LIVENESS}

    def setup(self, world: Any) -> None:
        self.links: dict[str, Any] = {}  # channel place -> the model carrying it (see _plan)

    def start(self, ctx: ActionContext) -> None:
        self.state = ctx.state
        self.state.now = ctx.now
        self.state.patience = self.params["give_up"]
        self.until = ctx.now + self.params["period"]

    def poll(self, ctx: ActionContext) -> Status:
        if ctx.world is not None and ctx.now < self.until - 1e-9:
            return Status.RUNNING
        state = self.state
        missing = state.missing()
        if missing and ctx.now - state.last_news > self.params["give_up"] and not state.gave_up >= set(missing):
            if not state.gave_up >= set(missing):
                state.gave_up |= set(missing)
                ctx.emit("comm.gave_up", silent=sorted(missing))
        _plan(ctx, state, self.links)
        return Status.OK

    needs_world = True


class Send(InstantAction):
    """Process 5: the next message waiting for ``peer`` into the channel place towards it
    (the packet is that place's token; the agent's work loop gets a plain token back)."""

    params = {"peer": Param(str, doc="the peer agent"),
              "box": Param(str, doc="the channel place towards it", places="")}
    agent_state = CommAgent

    def run(self, ctx: ActionContext) -> None:
        state = ctx.state
        message = state.take(self.params["peer"])
        if message is None:
            raise ActionFailure(f"comm.send: nothing waiting for {self.params['peer']!r}")
        state.met(self.params["peer"])  # it hears the peer here
        ctx.put(self.params["box"], {"size": message.size, "payload": message.payload, "code": message.code,
                                     "message": message})
        ctx.emit("comm.sent", to=self.params["peer"], code=message.code, bytes=message.size,
                 payload=message.payload, source=message.source)


class Receive(InstantAction):
    """Take one message from a channel place into this agent's history and map.

    The token may be the run's loss notice instead (``{"lost": True, "why": ...,
    "data": <the packet>}``: the radio model lost the frame, and the comm radio's
    ``on_loss`` is ``notify``): the slot goes back all the same, so the pair can talk
    again, and the lost message is kept for TCP's retransmission
    (:meth:`~petriflow.agents.comm.agent.CommAgent.keep_lost`): it is taken in, before
    anything newer from that sender, when a later message of it gets through or when
    this agent's next plan hears it."""

    params = {"box": Param(str, doc="the channel place", places="")}
    agent_state = CommAgent

    def run(self, ctx: ActionContext) -> None:
        state = ctx.state
        packet = ctx.inputs[self.params["box"]][0]
        notice = isinstance(packet, dict) and packet.get("lost") is True
        if notice:
            packet = packet.get("data")
        message = packet.get("message") if isinstance(packet, dict) else None
        if message is None:
            raise ActionFailure(f"comm.receive: the token of {self.params['box']!r} carries no message")
        state.now = ctx.now
        sender = state.by_address(message.sender)
        name = sender.name if sender is not None else str(message.sender)
        if notice:
            state.keep_lost(name, message)
            ctx.emit("comm.lost", sender=name, code=message.code, bytes=message.size, source=message.source)
            return
        for earlier in state.resend(name):  # a later frame got through: so does TCP's retransmission
            _take_in(ctx, state, earlier, resent=True)
        _take_in(ctx, state, message)


def has_message(state: CommAgent | None, params: dict[str, Any]) -> bool:
    """Guard (reads ``outbox/{peer}``): the agent has a message waiting for
    ``params['peer']`` and hears it."""
    return state is not None and state.has_for(params["peer"])


def _done(state: CommAgent) -> bool:
    if state.kind == "robot" and not state.explored:
        return False
    if not state.complete_sources(state.gave_up):  # the cheap test first: most often it decides
        return False
    silent = {name for name, peer in state.peers.items()
              if peer.address in state.gave_up or state.now - state.heard.get(name, state.since) > state.patience}
    waiting = any(box for name, box in state.outbox.items() if name not in silent) \
        or any(lost for name, lost in state.lost.items() if name not in silent)  # a retransmission to come
    return not waiting and not state.untold()


def finished(state: CommAgent | None, params: dict[str, Any]) -> bool:
    """Guard (reads ``*``): the agent holds the whole map and has nothing left to send
    (or gave up)."""
    if state is None:
        return False
    if state.finished or _done(state):
        state.finished = True
        return True
    return False


def going_on(state: CommAgent | None, params: dict[str, Any]) -> bool:
    """Guard (reads ``*``): the agent is not finished."""
    return not finished(state, params)


#: ``{name: (guard, the state keys it reads)}``: ``f(state, params) -> bool`` over the
#: agent's :class:`CommAgent`, asked again only when one of its keys changed.
GUARDS = {"comm.has_message": (has_message, ("outbox/{peer}",)),
          "comm.finished": (finished, ("*",)),
          "comm.going_on": (going_on, ("*",))}
