"""Legged robots: kinematics, gaits and the SMART robots Robot3L and Robot4L (seed 003).

* :mod:`~petriflow.agents.legged.kinematics`: one leg (hip, knee, ext) by screw theory.
* :mod:`~petriflow.agents.legged.robots`: the two designs and their URDFs.
* :mod:`~petriflow.agents.legged.stability`: support polygon and stability margin.
* :mod:`~petriflow.agents.legged.gait`: Robot4L's crawl and Robot3L's sliding gait.
* :mod:`~petriflow.agents.legged.control`: a robot body in a pybullet world.
* :mod:`~petriflow.agents.legged.righting`: standing a fallen robot up, bracing it.
* :mod:`~petriflow.agents.legged.actions`: ``gait.walk``, ``gait.turn``, ``gait.brace``,
  ``gait.stand_up`` (registered by :mod:`~petriflow.agents.legged.plugin`).

See ``README.md`` beside this file for the dimensions, conventions and design choices.
"""
