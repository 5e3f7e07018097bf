"""Bidding-based collaborative mapping by a robot team (seed 004, Hentout et al. 2020).

The pure core, one concept per module; nothing here imports pybullet:

* :mod:`~petriflow.agents.bidding.cost`: eq. 6, a robot's bid for a zone, vectorised
  over robots x zones.
* :mod:`~petriflow.agents.bidding.auction`: autonomous deployment (one call for
  proposals per zone in rank order), re-auction after a breakdown, and the operator's
  random deployment lists of Tables 3-6.
* :mod:`~petriflow.agents.bidding.protocol`: the ten protocol messages, their
  expected counts for one mission, and a counter for a run.
* :mod:`~petriflow.agents.bidding.laser`: laser returns to world points (eq. 7-8).
* :mod:`~petriflow.agents.bidding.grid`: the interface agent's global occupancy grid
  and the map accuracy of eq. 10 against a ground truth rasterised from the world.
* :mod:`~petriflow.agents.bidding.office`: the 32 m x 22 m office of Fig. 6 (and
  generated ones) as a world description, with a top-view picture.
"""
