"""The SMART scenario (seed 003): command messages and the actions that tie vision,
planning and gaits to its workflow net (``nets/smart/``).

| module | one concept |
|---|---|
| ``messages`` | SMART command frames: action id, robot id, ``,`` parameters, ``%`` |
| ``arena`` | the arena as the camera sees it: white floor, marker hats (world ``meta.smart``) |
| ``decision`` | what the decision maker reads in a scene: upright, down or missing |
| ``actions`` | ``smart.capture``, ``.dispatch``, ``.send``, ``.follow``, ``.avoid``, ``.push`` |
| ``guards`` | ``smart.help_needed`` (the AND-split T5 fires on a fallen robot) |
| ``timing`` | wall-clock split of a run: render, vision, planning, physics, control, net |
| ``draw`` | top-view pictures with OpenCV |
| ``experiments`` | ``python -m petriflow.agents.smart.experiments {reinsertion,crossing,helping,all}`` |
"""
