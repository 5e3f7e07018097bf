"""The kinematic world mode: poses integrated in arrays agree with pybullet's dynamics,
rays asked for on demand come back as single rays do, the default mode is unchanged."""

import math

import pytest

from petriflow.errors import NetFormatError, PetriflowError
from petriflow.world import World

URDF = "petriflow.agents:robots/diffdrive.urdf"


def _world(mode, drive="diff", boxes=()):
    return World({"dt": 0.05, "gravity": 0.0, "plane": False, "mode": mode, "boxes": list(boxes),
                  "robots": [{"id": "r", "urdf": URDF, "position": [0.5, -0.25], "yaw": 0.3, "z": 0.5,
                              "drive": drive}]})


def _drive(world, v, w, steps, vy=0.0):
    world.command("r", v=v, w=w, vy=vy)
    for _ in range(steps):
        world.step()
    return world.pose("r")


@pytest.mark.parametrize("v, w", [(0.4, 0.0), (0.3, 0.8), (0.0, -1.2)])
def test_kinematic_and_dynamic_modes_agree_on_straight_drives_and_turns(v, w):
    kinematic, dynamic = _world("kinematic"), _world("dynamic")
    try:
        a, b = _drive(kinematic, v, w, 60), _drive(dynamic, v, w, 60)
        assert math.dist(a[:2], b[:2]) < 0.01
        assert abs(math.remainder(a[2] - b[2], math.tau)) < 0.01
        # and the robot really moved as commanded (3 simulated seconds)
        if w == 0:
            assert math.dist(a[:2], (0.5, -0.25)) == pytest.approx(v * 3.0, rel=1e-6)
        else:
            assert math.remainder(a[2] - 0.3 - w * 3.0, math.tau) == pytest.approx(0.0, abs=1e-9)
    finally:
        kinematic.close()
        dynamic.close()


def test_a_holonomic_robot_moves_sideways_and_a_diff_robot_may_not():
    world = _world("kinematic", drive="holonomic")
    try:
        x, y, yaw = _drive(world, 0.0, 0.0, 20, vy=0.5)
        assert (x, y) == pytest.approx((0.5 - 0.5 * math.sin(0.3), -0.25 + 0.5 * math.cos(0.3)))
    finally:
        world.close()
    world = _world("kinematic")
    try:
        with pytest.raises(PetriflowError, match="sideways"):
            world.command("r", vy=0.1)
    finally:
        world.close()


def test_poses_reach_pybullet_only_when_read():
    world = _world("kinematic")
    try:
        p, body = world.p, world.body("r")
        _drive(world, 0.5, 0.0, 20)
        assert p.getBasePositionAndOrientation(body, physicsClientId=world.client)[0][0] == pytest.approx(0.5)
        world.sync()
        x, y, _ = world.pose("r")
        assert p.getBasePositionAndOrientation(body, physicsClientId=world.client)[0][:2] == pytest.approx((x, y))
        # a ray that may hit robots writes the poses back first and finds the robot where it is now
        _drive(world, 0.5, 0.0, 20)
        x, y, _ = world.pose("r")
        # (at the body's height: its cylinder spans 0.04 to 0.12 m above the base link's z of 0.5)
        hit = world.rays([(x, y + 2.0, 0.58)], [(x, y - 2.0, 0.58)])[0]
        assert hit[0] == body
    finally:
        world.close()


def _maze_world(robots=8):
    boxes = [{"id": f"wall{i}", "size": [0.1, 1.5, 0.4], "position": [1.0 + i, (-1) ** i * 0.7, 0.2]}
             for i in range(6)]
    return World({"dt": 0.1, "gravity": 0.0, "mode": "kinematic", "boxes": boxes,
                  "robots": [{"id": f"r{i}", "urdf": URDF, "position": [0.5 + 0.7 * i, 0.1 * i], "z": 0.05}
                             for i in range(robots)]})


def test_a_batch_of_requested_rays_returns_what_single_rays_return():
    world = _maze_world()
    try:
        p = world.p
        requests, singles = [], []
        for i in range(8):
            x, y, _ = world.pose(f"r{i}")
            starts = [(x, y, 0.1)] * 4
            ends = [(x + 3 * math.cos(a), y + 3 * math.sin(a), 0.1) for a in (0, math.pi / 2, math.pi, -math.pi / 2)]
            requests.append(world.request_rays(starts, ends))
            world.sync()
            singles.append([p.rayTest(s, e, physicsClientId=world.client)[0] for s, e in zip(starts, ends)])
        assert not any(r.ready for r in requests)
        world.step()                          # one batch for every request of the tick
        walls = {world.body(f"wall{i}") for i in range(6)}
        seen = 0
        for request, single in zip(requests, singles):
            assert request.ready
            for (body, fraction, point), hit in zip(request.hits, single):
                if hit[0] in walls or hit[0] == -1:  # the single ray also sees robots; the request does not
                    assert body == hit[0] and fraction == pytest.approx(hit[2]) and point == pytest.approx(hit[3])
                    seen += body in walls
        assert seen >= 4
        # rays that see robots too: the batch and single rays agree on every ray
        x, y, _ = world.pose("r0")
        ends = [(x + 6 * math.cos(a), y + 6 * math.sin(a), 0.1) for a in [i * 0.3 for i in range(21)]]
        batch = world.rays([(x, y, 0.5)] * len(ends), ends)
        for (body, fraction, _), end in zip(batch, ends):
            hit = p.rayTest((x, y, 0.5), end, physicsClientId=world.client)[0]
            assert body == hit[0] and fraction == pytest.approx(hit[2])
    finally:
        world.close()


def test_a_robot_written_back_stands_where_it_was_loaded():
    world = _world("kinematic")         # a body whose centre of mass is 8 cm above its base link
    try:
        p, body = world.p, world.body("r")
        loaded = [p.getAABB(body, link, physicsClientId=world.client) for link in range(-1, 3)]
        world.set_pose("r", *world.pose("r"))
        world.sync()
        for link, (low, high) in zip(range(-1, 3), loaded):
            now_low, now_high = p.getAABB(body, link, physicsClientId=world.client)
            assert now_low == pytest.approx(low, abs=1e-6) and now_high == pytest.approx(high, abs=1e-6)
    finally:
        world.close()


def test_robots_nothing_reads_leave_the_scene_and_come_back_where_they_are_when_read():
    world = _maze_world()
    try:
        p, client = world.p, world.client
        from petriflow.world import ROBOT_GROUP

        starts, ends = [], []
        for i in range(8):
            x, y, _ = world.pose(f"r{i}")
            starts += [(x, y - 1.0, 0.1), (x - 0.6, y, 0.1)]
            ends += [(x, y + 1.0, 0.1), (x + 3.0, y, 0.1)]
        scene = [(h[0], h[2]) for h in p.rayTestBatch(starts, ends, collisionFilterMask=0xFFFF & ~ROBOT_GROUP,
                                                      physicsClientId=client)]
        world.command("r3", v=0.5)
        world.step()
        assert [(b, f) for b, f, _ in world.rays(starts, ends, robots=False)] == scene
        x, y, _ = world.pose("r3")
        parked = p.getBasePositionAndOrientation(world.body("r3"), physicsClientId=client)[0]
        assert math.dist(parked[:2], (x, y)) > 100.0              # out of the scene's way
        assert p.rayTest((x, y - 1.0, 0.1), (x, y + 1.0, 0.1), physicsClientId=client)[0][0] != world.body("r3")
        # a ray that sees robots brings every robot back where the arrays say, for good
        assert world.rays([(x, y - 1.0, 0.1)], [(x, y + 1.0, 0.1)])[0][0] == world.body("r3")
        for i in range(8):
            back = p.getBasePositionAndOrientation(world.body(f"r{i}"), physicsClientId=client)[0]
            assert back[:2] == pytest.approx(world.pose(f"r{i}")[:2])
        world.rays(starts, ends, robots=False)
        assert p.getBasePositionAndOrientation(world.body("r3"), physicsClientId=client)[0][:2] == pytest.approx((x, y))
    finally:
        world.close()


def test_robots_stay_in_a_world_that_steps_bodies_with_mass():
    world = World({"dt": 0.05, "mode": "kinematic", "boxes": [{"id": "crate", "size": [0.2, 0.2, 0.2],
                                                                "position": [3, 0, 0.1], "mass": 1.0}],
                   "robots": [{"id": "r", "urdf": URDF, "position": [0.5, 0.0], "z": 0.05}]})
    try:
        world.rays([(0, 0, 0.1)], [(5, 0, 0.1)], robots=False)
        where = world.p.getBasePositionAndOrientation(world.body("r"), physicsClientId=world.client)[0]
        assert where[:2] == pytest.approx((0.5, 0.0))
    finally:
        world.close()


def test_the_default_mode_stays_dynamic_and_bad_modes_are_refused():
    world = World({"robots": [{"id": "r", "urdf": URDF}]})
    try:
        assert world.mode == "dynamic" and not world.is_kinematic("r")
    finally:
        world.close()
    with pytest.raises(NetFormatError, match="mode is one of dynamic, kinematic"):
        World({"mode": "ghost"})
    with pytest.raises(NetFormatError, match="drive is one of"):
        World({"mode": "kinematic", "robots": [{"id": "r", "urdf": URDF, "drive": "tank"}]})


def test_a_legged_robot_keeps_its_dynamics_in_a_kinematic_world():
    world = World({"dt": 0.01, "mode": "kinematic", "robots": [
        {"id": "wheels", "urdf": URDF, "z": 0.05},
        {"id": "falling", "urdf": URDF, "position": [2, 0], "z": 1.0, "motion": "dynamic"}]})
    try:
        assert world.is_kinematic("wheels") and not world.is_kinematic("falling")
        for _ in range(50):
            world.step()
        assert world.p.getBasePositionAndOrientation(world.body("falling"), physicsClientId=world.client)[0][2] < 0.95
        assert world.pose("wheels") == (0.0, 0.0, 0.0)
    finally:
        world.close()
