"""The world description format, checked without pybullet.

A world file (``world.yaml``) is data a run builds a pybullet scene from (see
:mod:`petriflow.world`). :func:`check_world` checks every field before anything is
built or copied into a journal: known keys, types, finite numbers in physical ranges,
sizes that pybullet will not silently change, ids that are unique. An error is one
line naming the file, the line and the element::

    world.yaml:12: 'wall': size must be 3 numbers > 0 (x, y, z extents in m), got [1]

Limits (the same for every world; they keep a run finite and pybullet's behaviour
defined): ``dt`` from 0.0001 to 1 s; coordinates within 10 km; sizes up to 1 km;
cameras up to 4096 x 4096 pixels; at most 100,000 bodies.

Examples:
    >>> check_world({"dt": 0.01, "boxes": [{"id": "wall", "size": [2, 0.1, 0.5], "position": [0, 1, 0.25]}]})["dt"]
    0.01
    >>> check_world({"dt": 1e-9}, path="w.yaml")
    Traceback (most recent call last):
    ...
    petriflow.errors.NetFormatError: w.yaml: dt must be a number of seconds from 0.0001 to 1, got 1e-09
"""

from __future__ import annotations

import math
from typing import Any, Mapping

from petriflow import limits
from petriflow.errors import NetFormatError, did_you_mean

__all__ = ["check_world", "check_box", "WorldDescription", "COLOURS", "MIN_DT", "MAX_DT", "MODES", "DRIVES"]

#: Named colours (RGBA) a description may use.
COLOURS = {
    "red": (0.9, 0.1, 0.1, 1.0),
    "blue": (0.1, 0.2, 0.9, 1.0),
    "yellow": (0.95, 0.85, 0.1, 1.0),
    "green": (0.1, 0.75, 0.2, 1.0),
    "black": (0.02, 0.02, 0.02, 1.0),
    "white": (1.0, 1.0, 1.0, 1.0),
    "grey": (0.45, 0.45, 0.45, 1.0),
    "orange": (1.0, 0.55, 0.0, 1.0),
}

#: The shortest and longest physics step a world may take (seconds).
MIN_DT, MAX_DT = 1e-4, 1.0
_FAR = 1e4          # metres: coordinates beyond this are a typo, not a scene
_BIG = 1e3          # metres: the largest box extent

_KEYS = {"dt", "gravity", "plane", "boxes", "grid", "robots", "cameras", "meta", "mode"}
_BOX_KEYS = {"id", "size", "position", "yaw", "colour", "mass"}
_GRID_KEYS = {"cell", "height", "origin", "rows", "colour"}
_ROBOT_KEYS = {"id", "urdf", "position", "yaw", "roll", "pitch", "colour", "agent", "z", "motion", "drive"}

#: World modes: ``dynamic`` (every robot a physics body, stepped by pybullet: the default)
#: and ``kinematic`` (robots without mass whose poses the world integrates, see
#: :mod:`petriflow.world`).
MODES = ("dynamic", "kinematic")
#: Motion models of a kinematic robot: ``diff`` and ``unicycle`` follow a forward speed
#: and a turn rate, ``holonomic`` also a sideways speed.
DRIVES = ("diff", "unicycle", "holonomic")
_CAMERA_KEYS = {"id", "position", "target", "up", "fov", "width", "height"}


class WorldDescription(dict):
    """A world description :func:`check_world` checked: every field typed, defaults
    filled in (a :class:`petriflow.world.World` builds one without checking it again)."""


class _Checker:
    def __init__(self, path: str | None) -> None:
        self.path = path
        self.ids: set[str] = set()

    def fail(self, message: str, item: Any = None, element: str | None = None) -> None:
        raise NetFormatError(message, path=self.path, line=getattr(item, "line", None), element=element)

    def mapping(self, item: Any, keys: set[str], what: str, element: str | None = None) -> Mapping[str, Any]:
        if not isinstance(item, Mapping):
            self.fail(f"a {what} is a mapping, got {item!r}", item, element)
        for key in item:
            if key not in keys:
                self.fail(f"unknown key {key!r} in {what}{did_you_mean(str(key), keys)}", item,
                          element or _id(item))
        return item

    def number(self, value: Any, what: str, item: Any, element: str | None, low: float = -_FAR,
               high: float = _FAR, *, low_open: bool = False) -> float:
        if isinstance(value, bool) or not isinstance(value, (int, float)):
            self.fail(f"{what} must be a number, got {value!r}", item, element)
        value = float(value)
        if not math.isfinite(value) or value > high or value < low or (low_open and value == low):
            bound = f"{'>' if low_open else '>='} {low:g} and <= {high:g}"
            self.fail(f"{what} must be a finite number {bound}, got {value!r}", item, element)
        return value

    def vector(self, value: Any, size: int, what: str, item: Any, element: str | None, low: float = -_FAR,
               high: float = _FAR, low_open: bool = False, hint: str = "") -> tuple[float, ...]:
        if not isinstance(value, (list, tuple)) or len(value) != size:
            self.fail(f"{what} must be {size} numbers{hint}, got {value!r}", item, element)
        return tuple(self.number(v, what, item, element, low, high, low_open=low_open) for v in value)

    def text(self, value: Any, what: str, item: Any, element: str | None) -> str:
        if not isinstance(value, str) or not value:
            self.fail(f"{what} must be text, got {value!r}", item, element)
        return value

    def body_id(self, value: Any, item: Any) -> str:
        body = self.text(value, "id", item, None)
        if body in self.ids:
            self.fail("duplicate body id", item, body)
        self.ids.add(body)
        if len(self.ids) > limits.WORLD_BODIES:
            self.fail(f"more than {limits.WORLD_BODIES:,} bodies", item, body)
        return body

    def colour(self, value: Any, item: Any, element: str | None) -> tuple[float, ...]:
        if isinstance(value, str):
            if value not in COLOURS:
                self.fail(f"unknown colour {value!r}{did_you_mean(value, COLOURS)}", item, element)
            return COLOURS[value]
        if isinstance(value, (list, tuple)) and len(value) in (3, 4):
            rgba = tuple(self.number(v, "a colour component", item, element, 0.0, 1.0) for v in value)
            return rgba + ((1.0,) if len(rgba) == 3 else ())
        self.fail(f"a colour is a name ({', '.join(COLOURS)}) or [r, g, b(, a)] from 0 to 1, got {value!r}",
                  item, element)


def _id(item: Any) -> str | None:
    return item.get("id") if isinstance(item, Mapping) and isinstance(item.get("id"), str) else None


def _list(check: _Checker, value: Any, what: str, parent: Any) -> list:
    if value is None:
        return []
    if not isinstance(value, list):
        check.fail(f"'{what}' must be a list, got {value!r}", parent)
    return value


def _box(check: _Checker, box: Mapping[str, Any], body: str) -> dict[str, Any]:
    return {
        "id": body,
        "size": check.vector(box["size"], 3, "size", box, body, 0.0, _BIG, low_open=True,
                             hint=" > 0 (x, y, z extents in m)"),
        "position": check.vector(box["position"], 3, "position", box, body, hint=" (x, y, z in m)"),
        "yaw": check.number(box.get("yaw", 0.0), "yaw", box, body),
        "colour": check.colour(box.get("colour", "grey"), box, body),
        "mass": check.number(box.get("mass", 0.0), "mass", box, body, 0.0, 1e6),
    }


def check_box(box: Mapping[str, Any], path: str | None = None) -> dict[str, Any]:
    """One box (the fields of a world's ``boxes`` entry), checked as :func:`check_world`
    checks it; its colour becomes RGBA.

    Examples:
        >>> check_box({"id": "crate", "size": [0.3, 0.3, 0.2], "position": [1, 0, 0.1], "colour": "black"})["colour"]
        (0.02, 0.02, 0.02, 1.0)
    """
    check = _Checker(path)
    return _box(check, box, check.text(box.get("id"), "id", box, None))


def check_world(data: Any, path: str | None = None) -> WorldDescription:
    """Check a world description and return it with every number as a float and every
    vector as a tuple, defaults filled in (what :class:`petriflow.world.World` builds).

    Raises:
        NetFormatError: one line naming the file, the line and the element.
    """
    check = _Checker(path)
    if data is None:
        data = {}
    world = check.mapping(data, _KEYS, "world description")
    out: dict[str, Any] = {
        "dt": 1.0 / 240.0, "gravity": -9.81, "plane": True, "boxes": [], "grid": None, "robots": [],
        "cameras": [], "meta": {}, "mode": "dynamic",
    }
    if "mode" in world:
        if world["mode"] not in MODES:
            check.fail(f"mode is one of {', '.join(MODES)}, got {world['mode']!r}", world)
        out["mode"] = world["mode"]
    if "dt" in world:
        dt = world["dt"]
        if isinstance(dt, bool) or not isinstance(dt, (int, float)) or not MIN_DT <= float(dt) <= MAX_DT:
            check.fail(f"dt must be a number of seconds from {MIN_DT:g} to {MAX_DT:g}, got {dt!r}", world)
        out["dt"] = float(dt)
    if "gravity" in world:
        out["gravity"] = check.number(world["gravity"], "gravity", world, None, -1000.0, 1000.0)
    if "plane" in world:
        if not isinstance(world["plane"], bool):
            check.fail(f"plane must be true or false, got {world['plane']!r}", world)
        out["plane"] = world["plane"]
    if world.get("meta") is not None:
        if not isinstance(world["meta"], Mapping):
            check.fail(f"meta is a mapping, got {world['meta']!r}", world)
        out["meta"] = world["meta"]
    if out["plane"]:
        check.ids.add("plane")
    for box in _list(check, world.get("boxes"), "boxes", world):
        box = check.mapping(box, _BOX_KEYS, "box")
        if "id" not in box or "size" not in box or "position" not in box:
            check.fail("a box needs 'id', 'size' and 'position'", box, _id(box))
        out["boxes"].append(_box(check, box, check.body_id(box["id"], box)))
    if world.get("grid") is not None:
        grid = check.mapping(world["grid"], _GRID_KEYS, "grid", "grid")
        rows = _list(check, grid.get("rows"), "rows", grid)
        if not all(isinstance(r, str) and set(r) <= {"#", "."} for r in rows):
            check.fail("grid rows are strings of '#' (occupied) and '.' (free)", grid, "grid")
        if len(rows) > 1000 or any(len(r) > 1000 for r in rows):
            check.fail("a grid has at most 1000 rows of at most 1000 cells", grid, "grid")
        out["grid"] = {
            "cell": check.number(grid.get("cell", 0.25), "cell", grid, "grid", 0.0, 100.0, low_open=True),
            "height": check.number(grid.get("height", 0.4), "height", grid, "grid", 0.0, _BIG, low_open=True),
            "origin": check.vector(grid.get("origin", (0.0, 0.0)), 2, "origin", grid, "grid", hint=" (x, y in m)"),
            "rows": list(rows),
            "colour": check.colour(grid.get("colour", "grey"), grid, "grid"),
        }
        runs = sum(row.count(".#") + row.startswith("#") for row in rows)  # one box per run of '#'
        if runs + len(check.ids) > limits.WORLD_BODIES:
            check.fail(f"more than {limits.WORLD_BODIES:,} bodies", grid, "grid")
    for robot in _list(check, world.get("robots"), "robots", world):
        robot = check.mapping(robot, _ROBOT_KEYS, "robot")
        if "id" not in robot or "urdf" not in robot:
            check.fail("a robot needs 'id' and 'urdf'", robot, _id(robot))
        body = check.body_id(robot["id"], robot)
        entry = {
            "id": body,
            "urdf": check.text(robot["urdf"], "urdf", robot, body),
            "position": check.vector(robot.get("position", (0.0, 0.0)), 2, "position", robot, body,
                                     hint=" (x, y in m)"),
            "agent": check.text(robot.get("agent", body), "agent", robot, body),
        }
        for key, default in (("z", 0.0), ("yaw", 0.0), ("roll", 0.0), ("pitch", 0.0)):
            entry[key] = check.number(robot.get(key, default), key, robot, body)
        if "colour" in robot:
            entry["colour"] = check.colour(robot["colour"], robot, body)
        entry["motion"] = robot.get("motion", "kinematic" if out["mode"] == "kinematic" else "dynamic")
        if entry["motion"] not in MODES:
            check.fail(f"motion is one of {', '.join(MODES)}, got {entry['motion']!r}", robot, body)
        entry["drive"] = robot.get("drive", "diff")
        if entry["drive"] not in DRIVES:
            hint = did_you_mean(str(entry["drive"]), DRIVES)
            check.fail(f"drive is one of {', '.join(DRIVES)}, got {entry['drive']!r}{hint}", robot, body)
        out["robots"].append(entry)
    seen_cameras: set[str] = set()
    for camera in _list(check, world.get("cameras"), "cameras", world):
        camera = check.mapping(camera, _CAMERA_KEYS, "camera")
        name = check.text(camera.get("id", "camera"), "id", camera, None)
        if name in seen_cameras:
            check.fail("duplicate camera id", camera, name)
        seen_cameras.add(name)
        entry = {
            "id": name,
            "position": check.vector(camera.get("position", (0, 0, 5)), 3, "position", camera, name),
            "target": check.vector(camera.get("target", (0, 0, 0)), 3, "target", camera, name),
            "up": check.vector(camera.get("up", (0, 1, 0)), 3, "up", camera, name),
            "fov": check.number(camera.get("fov", 60), "fov", camera, name, 0.0, 179.0, low_open=True),
        }
        for key, default in (("width", 640), ("height", 480)):
            value = camera.get(key, default)
            if isinstance(value, bool) or not isinstance(value, int) or not 1 <= value <= limits.CAMERA_PIXELS:
                check.fail(f"{key} must be a whole number of pixels from 1 to {limits.CAMERA_PIXELS}, got {value!r}",
                           camera, name)
            entry[key] = value
        look = [t - p for t, p in zip(entry["target"], entry["position"])]
        cross = (look[1] * entry["up"][2] - look[2] * entry["up"][1], look[2] * entry["up"][0] - look[0] * entry["up"][2],
                 look[0] * entry["up"][1] - look[1] * entry["up"][0])
        if math.hypot(*look) < 1e-9:
            check.fail("the camera's target is where the camera is", camera, name)
        if math.hypot(*cross) < 1e-9:
            check.fail("the camera's up is along its line of sight", camera, name)
        out["cameras"].append(entry)
    return WorldDescription(out)
