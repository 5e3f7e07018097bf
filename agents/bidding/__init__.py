"""Bidding-based collaborative mapping by a robot team (seed 004, Hentout et al. 2020).

One concept per module:

* :mod:`~petriflow.agents.bidding.cost`: eq. 6, a robot's bid for a zone, vectorised
  over robots x zones.
* :mod:`~petriflow.agents.bidding.auction`: autonomous deployment (one call for
  proposals per zone in rank order), re-auction after a breakdown, the operator's
  random deployment lists, the nearest-first visiting order.
* :mod:`~petriflow.agents.bidding.protocol`: the ten protocol messages, broadcasts and
  the agents' mailboxes.
* :mod:`~petriflow.agents.bidding.agent`: the operator's, the HMIA's and a robot
  agent's state (agent states the run keeps; the guards read them by key).
* :mod:`~petriflow.agents.bidding.actions`: the agents' steps as actions, and the
  guards that route their work loops.
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
