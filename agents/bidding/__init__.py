"""Bidding-based collaborative mapping by a robot team (seed 004, Hentout et al. 2020).

One concept per module:

* :mod:`~petriflow.agents.bidding.cost`: eq. 6, a robot's bid for a zone, vectorised
  over robots x zones.
* :mod:`~petriflow.agents.bidding.auction`: autonomous deployment (one call for
  proposals per zone in rank order), re-auction after a breakdown, the operator's
  random deployment lists, the nearest-first visiting order.
* :mod:`~petriflow.agents.bidding.protocol`: the ten message kinds and the payload the
  runtime's one message type carries for them.
* :mod:`~petriflow.agents.bidding.correspondent`: the base of every agent's state: its
  outbox (the runtime's), its broadcasts and message counts.
* :mod:`~petriflow.agents.bidding.agent`: the operator's, the HMIA's and a robot
  agent's state (agent states the run keeps; the guards read them by key).
* the agents' steps as actions: :mod:`~petriflow.agents.bidding.operator`,
  :mod:`~petriflow.agents.bidding.interface` (the HMIA),
  :mod:`~petriflow.agents.bidding.robot` (an RA's protocol steps),
  :mod:`~petriflow.agents.bidding.driving` (an RA's driving controller),
  :mod:`~petriflow.agents.bidding.receive` (the receive table, kind -> handler),
  :mod:`~petriflow.agents.bidding.mail` (sending), :mod:`~petriflow.agents.bidding.waiting`
  (waiting for news), with what they declare of the run in
  :mod:`~petriflow.agents.bidding.needs`.
* :mod:`~petriflow.agents.bidding.guards`: the guards that route the work loops.
* :mod:`~petriflow.agents.bidding.nets`: the mission as a workflow net for any team
  (built with :class:`~petriflow.netbuild.NetBuilder`).
* :mod:`~petriflow.agents.bidding.metrics`: mapping time (eq. 9), accuracy (eq. 10),
  messages.
* :mod:`~petriflow.agents.bidding.laser`: laser returns to world points (eq. 7-8).
* :mod:`~petriflow.agents.bidding.grid`: the interface agent's global occupancy grid
  and the map accuracy of eq. 10 against a ground truth rasterised from the world.
* :mod:`~petriflow.agents.bidding.office`: the 32 m x 22 m office of Fig. 6 (and
  generated ones) as a world description, with a top-view picture; the run's office
  plan (the ``bidding.office`` resource).
* :mod:`~petriflow.agents.bidding.figures`: the global maps and the Fig. 10 plots.
"""
