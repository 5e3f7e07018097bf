"""Where could seed 000's Table 9 monitor stand? Run Table 8's mission (robot3 breaks down
at 110 s; the monitor never joins) for each seed given, then test every maze cell for a
spot that hears both robot1 (where it finished) and robot3 (where it broke down) above
the framework's threshold, with the run's own radio model (distance and walls).

    .venv/bin/python scripts/monitor_placement.py 1 2 3

nets/comm/experiments/table9-placement.yaml uses seed 1's answer.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

from petriflow.runtime.scheduler import Scheduler
from petriflow.sweep.load import load_sweep
from petriflow.sweep.trial import build
from petriflow.world import World

ROOT = Path(__file__).resolve().parents[1]


def main(seeds: list[int]) -> None:
    spec = load_sweep(ROOT / "nets/comm/experiments/table9.yaml")
    for seed in seeds:
        params = dict(spec.rows[0].params, join_at=4000)  # past the run's end: Table 8's mission
        built = build(spec.to_data(), params, seed)
        world = World(built.world, base=Path(built.config.world).resolve().parent, path=str(built.config.world))
        try:
            scheduler = Scheduler(built.net, world=world, config=built.config, seed=seed, binding=built.binding)
            events: list = []
            scheduler.on_event(events.append, {"custom"})
            with scheduler:
                scheduler.run()
                finished = {e.agent: e.time for e in events if e.data.get("name") == "comm.explored"}
                radio = scheduler.channels.models["radio"]
                one, three = world.position("robot1"), world.position("robot3")
                spots = []
                cell, cols = 5 / 6, 6
                for i in range(cols):
                    for j in range(cols):
                        x, y = (i + 0.5) * cell, (j + 0.5) * cell
                        world.set_pose("monitor1", x, y, 0.0)
                        radio.bind(world)  # walls counted afresh for the moved monitor
                        a, b = radio.link_rssi("monitor1", "robot1"), radio.link_rssi("monitor1", "robot3")
                        if a > radio.threshold_dbm and b > radio.threshold_dbm:
                            spots.append(((round(x, 3), round(y, 3)), round(a, 1), round(b, 1)))
            spots.sort(key=lambda s: -min(s[1], s[2]))
            print(f"seed {seed}: robot1 finished at {finished.get('robot1')} s at ({one[0]:.2f}, {one[1]:.2f});"
                  f" robot3 broke down at ({three[0]:.2f}, {three[1]:.2f}), {math.dist(one, three):.2f} m away;"
                  f" threshold {radio.threshold_dbm} dBm ({radio.range():.2f} m in free space);"
                  f" cells that hear both (best first, dBm from robot1 / robot3): {spots or 'none'}")
        finally:
            world.close()


if __name__ == "__main__":
    main([int(s) for s in sys.argv[1:]] or [1])
