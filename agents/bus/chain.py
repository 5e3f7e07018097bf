"""The EMERGE chain as a pybullet robot: one hinge per module, generated from one
parameter set.

:func:`urdf` writes a chain of ``modules`` box segments, head first, and a short tail
cap; module ``mK``'s hinge (``mK_hinge``, a pitch joint about the y axis) joins its
segment to the one behind it (the last to the cap), so the chain moves by a vertical travelling wave, as a chain
of 1-DOF modules on a floor does. The modules' firmware drives its hinge by position
control (:func:`drive`, eq. 1's θ) and senses with a front proximity ray
(:func:`front_is_free`: the head's front sees nothing; every other module's front sees
the module in front of it).

:func:`world` is a world description holding the chain (its ``urdf`` written beside
the world file by ``python -m petriflow.agents.bus.chain``).

Examples:
    >>> text = urdf(3)
    >>> text.count("<joint "), "m3_hinge" in text, "tail" in text
    (3, True, True)
"""

from __future__ import annotations

import argparse
import math
from pathlib import Path
from typing import Any

__all__ = ["drive", "front_is_free", "joint_of", "urdf", "world"]

#: Segment size (m): length along the chain, width, height; mass (kg).
LENGTH, WIDTH, HEIGHT, MASS = 0.10, 0.08, 0.05, 0.15
#: Hinge torque limit (N m) and the proximity sensor's reach (m).
TORQUE, REACH = 1.5, 0.05


def _box(name: str, length: float, mass: float) -> str:
    size = f"{length} {WIDTH} {HEIGHT}"
    inertia = mass / 12.0
    return (f'  <link name="{name}">\n'
            f'    <visual><origin xyz="{-length / 2} 0 0"/><geometry><box size="{size}"/></geometry></visual>\n'
            f'    <collision><origin xyz="{-length / 2} 0 0"/><geometry><box size="{size}"/></geometry></collision>\n'
            f'    <inertial><origin xyz="{-length / 2} 0 0"/><mass value="{mass}"/>'
            f'<inertia ixx="{inertia * (WIDTH ** 2 + HEIGHT ** 2):.6g}" iyy="{inertia * (length ** 2 + HEIGHT ** 2):.6g}"'
            f' izz="{inertia * (length ** 2 + WIDTH ** 2):.6g}" ixy="0" ixz="0" iyz="0"/></inertial>\n'
            f'  </link>\n')


def urdf(modules: int) -> str:
    """The chain's URDF: ``modules`` segments head first, then a short tail cap; module
    ``mK``'s hinge joins its segment to the one behind it (the last to the cap)."""
    if not 1 <= modules <= 254:
        raise ValueError(f"a chain has 1 to 254 modules, got {modules}")
    parts = ['<?xml version="1.0"?>\n', f'<robot name="emerge_chain_{modules}">\n', _box("m1_segment", LENGTH, MASS)]
    for k in range(1, modules + 1):
        child = f"m{k + 1}_segment" if k < modules else "tail"
        parts.append(_box(child, LENGTH if k < modules else 0.02, MASS if k < modules else 0.03))
        parts.append(f'  <joint name="m{k}_hinge" type="revolute">\n'
                     f'    <parent link="m{k}_segment"/><child link="{child}"/>\n'
                     f'    <origin xyz="{-LENGTH} 0 0"/><axis xyz="0 1 0"/>\n'
                     f'    <limit lower="-1.57" upper="1.57" effort="{TORQUE}" velocity="6"/>\n'
                     f'  </joint>\n')
    parts.append("</robot>\n")
    return "".join(parts)


def world(modules: int, urdf_file: str, *, dt: float = 0.002) -> dict[str, Any]:
    """A world description: a floor and the chain along −x from the origin (its head
    at x = 0, facing +x)."""
    return {"dt": dt, "gravity": -9.81, "plane": True,
            "robots": [{"id": "chain", "urdf": urdf_file, "position": [0.0, 0.0], "z": HEIGHT / 2 + 0.002}],
            "meta": {"chain": {"modules": modules}}}


def _body(world: Any) -> int:
    return world.body("chain")


def joint_of(world: Any, module: str) -> tuple[int, int] | None:
    """``(body, joint index)`` of ``module``'s hinge, or ``None`` if the world's chain has none."""
    if "chain" not in world.bodies:
        return None
    p, body = world.p, _body(world)
    for j in range(p.getNumJoints(body, physicsClientId=world.client)):
        if p.getJointInfo(body, j, physicsClientId=world.client)[1].decode() == f"{module}_hinge":
            return body, j
    return None


def drive(world: Any, joint: tuple[int, int], angle: float) -> None:
    """Command the hinge to ``angle`` (rad) by position control."""
    body, index = joint
    world.p.setJointMotorControl2(body, index, world.p.POSITION_CONTROL, targetPosition=float(angle),
                                  force=TORQUE, physicsClientId=world.client)


def front_is_free(world: Any, module: str) -> bool:
    """The module's front proximity sensor: a ray from the front face of its segment,
    ``REACH`` m forward along it, hits nothing (the head's); every other module's
    front touches the segment of the module in front of it."""
    if "chain" not in world.bodies:
        return False
    p, body = world.p, _body(world)
    number = int(module[1:]) if module[1:].isdigit() else 0
    if number < 1 or number - 2 >= p.getNumJoints(body, physicsClientId=world.client):
        return False
    p.performCollisionDetection(physicsClientId=world.client)
    if number == 1:
        (x, y, z), orientation = p.getBasePositionAndOrientation(body, physicsClientId=world.client)
    else:  # segment K is the child of hinge K - 1 (joint index K - 2): its frame is its front face
        state = p.getLinkState(body, number - 2, computeForwardKinematics=True, physicsClientId=world.client)
        (x, y, z), orientation = state[4], state[5]
    matrix = p.getMatrixFromQuaternion(orientation)
    ahead = (matrix[0], matrix[3], matrix[6])  # the segment's x axis in the world
    if number == 1:  # the base's frame is its centre of mass: its front face is half a segment ahead
        x, y, z = x + LENGTH / 2 * ahead[0], y + LENGTH / 2 * ahead[1], z + LENGTH / 2 * ahead[2]
    own = -1 if number == 1 else number - 2
    behind = number - 1  # the link behind it: the next segment, or the tail cap
    # a ray that starts inside a box may or may not report it: ask for nearby surfaces
    # instead, and keep those ahead of the front face
    for link in range(-1, p.getNumJoints(body, physicsClientId=world.client)):
        if link in (own, behind):
            continue
        for point in p.getClosestPoints(body, body, REACH, linkIndexA=own, linkIndexB=link,
                                        physicsClientId=world.client):
            px, py, pz = point[6]  # on the other link
            if (px - x) * ahead[0] + (py - y) * ahead[1] + (pz - z) * ahead[2] > -0.005:
                return False
    return True


def pose(world: Any) -> tuple[float, float]:
    """The chain's mean position (x, y) over its segments."""
    p, body = world.p, _body(world)
    xs, ys = [], []
    for j in range(p.getNumJoints(body, physicsClientId=world.client)):
        position = p.getLinkState(body, j, physicsClientId=world.client)[0]
        xs.append(position[0])
        ys.append(position[1])
    return (sum(xs) / len(xs), sum(ys) / len(ys)) if xs else (math.nan, math.nan)


def main(argv: list[str] | None = None) -> None:
    """Write chain URDFs and worlds (``nets/bus/``)."""
    import yaml

    parser = argparse.ArgumentParser(description="write seed 002's chain robots and worlds")
    parser.add_argument("--out", default="nets/bus")
    parser.add_argument("--modules", type=int, nargs="+", default=[3, 20])
    args = parser.parse_args(argv)
    out = Path(args.out)
    for n in args.modules:
        (out / f"chain-{n}.urdf").write_text(urdf(n))
        (out / f"world-{n}.yaml").write_text(
            f"# A chain of {n} EMERGE modules on a floor (python -m petriflow.agents.bus.chain).\n"
            + yaml.safe_dump(world(n, f"chain-{n}.urdf"), sort_keys=False))
        print(f"wrote {out / f'chain-{n}.urdf'} and {out / f'world-{n}.yaml'}")


if __name__ == "__main__":
    main()
