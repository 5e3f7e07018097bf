"""The planning actions a net binds: ``planning.astar`` and ``planning.track``.

Both finish in the instant they fire (planning takes milliseconds of wall time and no
simulated time) and depend on no particular robot: they read token data and, for
``planning.track``, the world's pose of a body when no token gives one.

``planning.astar`` plans one robot's path on the camera's label map (seed 003 §4):
binary map for the robot, C-space by its radius, cells of n × n pixels, A*. It reads a
*scene*: the first input token that has a ``label_map`` (a mapping or an object), else
the newest token of the place its ``scene`` port names (a place the camera loop keeps
the latest scene in). A scene gives

* ``label_map``: ``uint8`` array, 0 floor, 1 obstacle, 2..5 red, blue, yellow, green;
* ``metres_per_pixel`` and ``origin`` (world ``[x, y]`` of the centre of pixel
  ``(0, 0)``; image rows run toward −y), or a ``frame``
  (:class:`~petriflow.agents.planning.maps.GridFrame`); the action's parameters of the
  same names stand in when the scene has none, and without an origin the image
  centre is the world origin;
* optionally ``poses`` (``{colour: [x, y, yaw]}``) for the start, and ``goal``
  (``[x, y]`` or ``{colour: [x, y]}``) when the transition gives none.

Its result (the output tokens' data) is ``{"robot", "path": [[x, y], ...], "start",
"goal", "variant", "steps", "length_m", "expanded", "visited"}``; a goal no path
reaches fails the action with the reason ``no path``. Wall-clock time is left out
unless ``report_ms`` is set, because it would make two runs' traces differ.

``planning.track`` checks a robot's position against its path after a move (§4.2):
the result's ``decision`` is ``on_track``, ``reinsert`` (with the ``point`` to head
for) or ``replan``; the guards ``planning.on_track``, ``planning.reinsert`` and
``planning.replan`` route tokens on it.

Examples:
    >>> import numpy as np
    >>> label = np.zeros((48, 64), np.uint8)
    >>> label[10:12, 10:12] = 2                          # the red robot
    >>> label[:30, 30:34] = 1                            # a wall
    >>> frame = GridFrame(0.05, origin=(0.0, 0.0))
    >>> result = plan_world_path(label, frame.with_cell(2), "red", goal=(2.5, -0.5), radius=0.1)
    >>> result["found"], result["start"], result["goal"], result["path"][-1]
    (True, [0.525, -0.525], [2.5, -0.5], [2.5, -0.5])
"""

from __future__ import annotations

import math
import time
from typing import Any, Mapping, Sequence

import numpy as np

from petriflow.agents.planning.astar import VARIANTS, astar
from petriflow.agents.planning.errors import PlanningError
from petriflow.agents.planning.maps import (
    ROBOT_LABELS,
    GridFrame,
    binary_map,
    cell_grid,
    free_cells_near,
    free_region,
    nearest_free,
    planning_grid,
    robot_centre,
    robot_label,
    segment_free,
)
from petriflow.agents.planning.tracking import check_track
from petriflow.capabilities import Poses, Positions, provides
from petriflow.runtime.action import ActionContext, InstantAction, Param, Port
from petriflow.runtime.stopwatch import UNTIMED, Timing

__all__ = ["PlanPath", "TrackPath", "plan_world_path", "scene_frame", "find_scene"]

_COLOURS = {label: colour for colour, label in ROBOT_LABELS.items()}
_OPTIONAL_FLOAT = (float, type(None))
_OPTIONAL_LIST = (list, tuple, type(None))


def _field(item: Any, name: str, default: Any = None) -> Any:
    """``item[name]`` for a mapping, ``item.name`` otherwise; ``default`` if absent or ``None``."""
    value = item.get(name) if isinstance(item, Mapping) else getattr(item, name, None)
    return default if value is None else value


def _tokens(ctx: ActionContext) -> list[Any]:
    return [data for place in sorted(ctx.inputs) for data in ctx.inputs[place] if data is not None]


def _point(value: Any, what: str) -> tuple[float, float]:
    try:
        x, y = (float(v) for v in list(value)[:2])
    except (TypeError, ValueError):
        raise PlanningError(f"{what} must be [x, y] in metres, got {value!r}") from None
    if not (math.isfinite(x) and math.isfinite(y)):
        raise PlanningError(f"{what} must be finite, got {value!r}")
    return x, y


def _colour(robot: str | int) -> str:
    return _COLOURS[robot_label(robot)]


def _for_robot(value: Any, robot: str | int) -> Any:
    """``value[colour]`` when ``value`` is keyed by robot, else ``value``."""
    if isinstance(value, Mapping):
        colour = _colour(robot)
        for key in (colour, robot, robot_label(robot), str(robot_label(robot))):
            if key in value:
                return value[key]
        return None
    return value


def find_scene(ctx: ActionContext) -> Any:
    """The scene an action plans in: the first input token with a ``label_map``, else
    the newest token of its ``scene`` port's place if it has one; ``None`` if neither."""
    for data in _tokens(ctx):
        if _field(data, "label_map") is not None:
            return data
    if "scene" in ctx.params:
        latest = ctx.latest("scene")
        if latest is not None and _field(latest, "label_map") is not None:
            return latest
    return None


def scene_frame(scene: Any, shape: Sequence[int], cell: int, metres_per_pixel: float | None = None,
                origin: Sequence[float] | None = None) -> GridFrame:
    """The scene's :class:`GridFrame` with cell size ``cell``; ``metres_per_pixel`` and
    ``origin`` stand in for what the scene lacks (no origin: image centre at 0, 0).

    Examples:
        >>> frame = scene_frame({"metres_per_pixel": 0.01}, (480, 640), 2)
        >>> [round(v, 6) for v in frame.origin], frame.cell
        ([-3.195, 2.395], 2)
    """
    frame = _field(scene, "frame")
    if isinstance(frame, GridFrame):
        return frame.with_cell(cell)
    scale = _field(scene, "metres_per_pixel", metres_per_pixel)
    if scale is None:
        raise PlanningError("the scene gives no metres_per_pixel and the action has none")
    flip_y = bool(_field(scene, "flip_y", True))
    where = _field(scene, "origin", origin)
    if where is None:  # the image centre at the world origin
        rows, cols = shape
        sign = 1.0 if flip_y else -1.0
        where = (-(cols - 1) / 2 * scale, sign * (rows - 1) / 2 * scale)
    return GridFrame(float(scale), _point(where, "origin"), cell, flip_y)


def plan_world_path(label_map: np.ndarray, frame: GridFrame, robot: str | int, goal: Sequence[float],
                    start: Sequence[float] | None = None, radius: float = 0.1, variant: str = "optimal",
                    cut_corners: bool = False, snap: float | None = None,
                    stopwatch: Timing = UNTIMED) -> dict[str, Any]:
    """Plan ``robot``'s path on a label map, in world coordinates.

    Args:
        label_map: the grey label map (0 floor, 1 obstacle, 2..5 robots).
        frame: where the map lies in the world, with the cell size to plan at.
        robot: the robot's colour or label.
        goal: world ``(x, y)`` to reach.
        start: world ``(x, y)`` to start from (default: the centre of the robot's
            pixels).
        radius: robot radius (m), by which obstacles are dilated.
        variant: ``"optimal"`` or ``"paper"`` (see :mod:`~petriflow.agents.planning.astar`).
        cut_corners: allow diagonal moves between two occupied cells.
        snap: a start or goal in an occupied cell moves to a free cell within this
            distance (m); default twice the radius (a goal on another robot, a robot
            pushed into an obstacle's margin). A goal moves to the nearest free cell.
            A start moves to the nearest free cell from which the goal can be reached
            and whose straight leg from the start crosses no obstacle itself, only the
            margin grown around it: a robot in the margin walks out of it.

    Returns:
        ``{"robot", "found", "path", "start", "goal", "variant", "steps", "length_m",
        "expanded", "visited", "seconds"}``; ``path`` is ``[]`` when no path exists.
        Its first point is the exact start (a start that was moved keeps it: the path's
        first leg leads from it to the free cell the search began at); its last point is
        the exact goal unless that was moved to a free cell; the others are cell centres.

    Raises:
        PlanningError: unknown robot, robot not on the map, start or goal blocked with
            no free cell within ``snap``.
    """
    label_map = np.asarray(label_map)
    colour = _colour(robot)
    if radius < 0:
        raise PlanningError(f"radius must be >= 0, got {radius}")
    grid = planning_grid(label_map, robot, radius / frame.metres_per_pixel, frame.cell)
    if start is None:
        centre = robot_centre(label_map, robot)
        if centre is None:
            raise PlanningError(f"robot {colour!r} is not on the label map")
        start = tuple(float(v) for v in frame.pixel_to_world(centre))
    start_xy, goal_xy = _point(start, "start"), _point(goal, "goal")
    reach = (2.0 * radius if snap is None else snap) / frame.metres_per_cell
    cells = {}
    for what, point in (("goal", goal_xy), ("start", start_xy)):
        cell = tuple(int(v) for v in frame.world_to_cell(point))
        free = nearest_free(grid, cell, reach)
        if free is None:
            raise PlanningError(f"{what} {list(point)} of robot {colour!r} is blocked (inside an obstacle "
                                f"grown by the robot radius, or off the map) and no free cell is within "
                                f"{reach * frame.metres_per_cell:g} m")
        if what == "start" and free != cell:
            free = _way_out(label_map, frame, robot, grid, start_xy, cell, cells["goal"][1], reach,
                            cut_corners)
        cells[what] = (cell, free)
    path: list[list[float]] = []
    plan = None
    if cells["start"][1] is not None:  # else free cells near, but none is a way out toward the goal
        with stopwatch.measure("search", keep=True):
            plan = astar(grid, cells["start"][1], cells["goal"][1], variant=variant, cut_corners=cut_corners)
    if plan is not None and plan.found:
        points = frame.cell_to_world(plan.cells)
        if cells["start"][0] == cells["start"][1]:
            points[0] = start_xy
        else:  # the way out of the margin: from where the robot stands to the free cell
            points = np.vstack([start_xy, points])
        if cells["goal"][0] == cells["goal"][1]:
            points[-1] = goal_xy
        path = np.round(points, 6).tolist()
    length = float(np.hypot(*np.diff(np.asarray(path), axis=0).T).sum()) if len(path) > 1 else 0.0
    return {
        "robot": colour, "found": bool(path), "path": path,
        "start": path[0] if path else [round(v, 6) for v in start_xy],
        "goal": path[-1] if path else [round(v, 6) for v in goal_xy],
        "variant": variant, "steps": plan.steps if plan is not None else 0, "length_m": round(length, 6),
        "expanded": plan.expanded if plan is not None else 0,
        "visited": plan.visited if plan is not None else 0,
        "seconds": plan.seconds if plan is not None else 0.0,
    }


def _way_out(label_map: np.ndarray, frame: GridFrame, robot: str | int, grid: np.ndarray,
             start: tuple[float, float], cell: tuple[int, int], goal: tuple[int, int], reach: float,
             cut_corners: bool) -> tuple[int, int] | None:
    """The free cell a start inside an obstacle's grown margin moves to: the nearest one
    within ``reach`` (cells) from which the search can reach the goal, and whose
    straight leg from the start crosses no obstacle itself (only its margin); ``None``
    if there is none."""
    region = free_region(grid, goal, cut_corners)
    obstacles = cell_grid(binary_map(label_map, robot), frame.cell)
    for row, col in free_cells_near(grid, cell, reach, region):
        if segment_free(obstacles, frame, start, frame.cell_to_world((row, col))):
            return int(row), int(col)
    return None


class PlanPath(InstantAction):
    """Plan a robot's path with A* on the camera's label map (seed 003 §4)."""

    params = {
        "robot": Param((str, int, type(None)), None, "robot colour (red, blue, yellow, green) or label 2..5; "
                       "default: the agent"),
        "goal": Param(_OPTIONAL_LIST, None, "goal [x, y] (m); default: the input token's goal"),
        "start": Param(_OPTIONAL_LIST, None, "start [x, y] (m); default: the token's pose of the robot, "
                       "else the centre of its pixels"),
        "radius": Param(float, 0.1, "robot radius (m): obstacles grow by it (C-space)", low=0),
        "cell": Param(int, 2, "cell side n in pixels (640x480 with n=2: a 320x240 grid)", low=1),
        "variant": Param(str, "optimal", "A* costs: optimal (sqrt 2 diagonals) or paper (cells travelled)",
                         choices=VARIANTS),
        "cut_corners": Param(bool, False, "allow a diagonal move between two occupied cells"),
        "snap": Param(_OPTIONAL_FLOAT, None, "a blocked start or goal moves to the nearest free cell within "
                      "this distance (m); default 2 x radius"),
        "metres_per_pixel": Param(_OPTIONAL_FLOAT, None, "pixel size (m) when the scene gives none"),
        "origin": Param(_OPTIONAL_LIST, None, "world [x, y] of pixel (0, 0) when the scene gives none"),
        "report_ms": Param(bool, False, "add the search's wall-clock ms to the result (traces then differ)"),
        "scene": Port("place holding the latest scene, read when no input token has one"),
    }

    def setup(self, world: Any) -> None:
        """Compile (or load) the search before the run: the first plan of a process
        would otherwise pay numba's compile, in its ``report_ms`` too."""
        from petriflow.agents.planning.astar import warm_up

        warm_up()

    def run(self, ctx: ActionContext) -> dict[str, Any]:
        params = self.params
        robot = params["robot"] if params["robot"] is not None else ctx.agent
        if robot is None:
            raise PlanningError("no robot: give params.robot or put the transition in a robot's subnet")
        colour = _colour(robot)
        scene = find_scene(ctx)
        if scene is None:
            raise PlanningError("no scene: no input token (nor the scene port's place) has a label_map")
        label_map = np.asarray(_field(scene, "label_map"))
        if label_map.ndim != 2:
            raise PlanningError(f"the label map must be 2-D, got shape {label_map.shape}")
        if params["cell"] < 1:
            raise PlanningError(f"cell must be >= 1 pixel, got {params['cell']}")
        frame = scene_frame(scene, label_map.shape, params["cell"], params["metres_per_pixel"],
                            params["origin"])
        goal = params["goal"]
        if goal is None:
            for data in [scene, *_tokens(ctx)]:
                goal = _for_robot(_field(data, "goal"), robot)
                if goal is not None:
                    break
        if goal is None:
            raise PlanningError(f"no goal for robot {colour!r}: give params.goal or a token with a goal")
        start = params["start"]
        if start is None:
            for data in [scene, *_tokens(ctx)]:
                poses = _field(data, "poses")
                start = _for_robot(poses, robot) if isinstance(poses, Mapping) else None
                if start is not None:
                    break
        began = time.perf_counter()
        with ctx.stopwatch.measure("planning", keep=True):
            result = plan_world_path(label_map, frame, robot, goal, start, params["radius"], params["variant"],
                                     params["cut_corners"], params["snap"], stopwatch=ctx.stopwatch)
        took = time.perf_counter() - began
        del result["seconds"]  # wall-clock: only on request
        if params["report_ms"]:
            result["ms"] = round(took * 1000.0, 3)
        if not result["found"]:
            raise PlanningError(f"no path for robot {colour!r} from {result['start']} to {result['goal']}")
        del result["found"]
        return result


class TrackPath(InstantAction):
    """Check a robot's position against its planned path (seed 003 §4.2): on track,
    reinsert at a point, or re-plan."""

    params = {
        "robot": Param((str, int, type(None)), None,
                       "the robot (colour, label or body name); default: the agent"),
        "step": Param(float, 0.05, "dmin: length of one standard move (m)", low=1e-9),
        "radius": Param(float, 0.1, "r: robot radius (m); farther than this from the path, re-plan",
                        low=1e-9),
        "reach": Param(_OPTIONAL_FLOAT, None, "longest single move (m), the reinsertion search radius; "
                       "default 2 x step"),
    }

    def _position(self, ctx: ActionContext, robot: Any) -> tuple[float, float]:
        for data in _tokens(ctx):
            pose = _field(data, "pose")
            if pose is not None:
                return _point(pose, "pose")
            poses = _field(data, "poses")
            if isinstance(poses, Mapping):
                try:
                    pose = _for_robot(poses, robot)
                except PlanningError:  # a body name, not a colour
                    pose = poses.get(robot)
                if pose is not None:
                    return _point(pose, "pose")
        world = ctx.world
        # a world is optional (tokens may carry the pose): its pose, else its position, if it has them
        reads = [world.pose] if provides(world, Poses) else []
        reads += [world.position] if provides(world, Positions) else []
        if robot is not None:
            for read in reads:
                try:
                    found = read(robot)
                except Exception as exc:  # a world that does not know the body
                    raise PlanningError(f"cannot read the pose of {robot!r}: {exc}") from None
                if found is not None:
                    return _point(found, "pose")
        raise PlanningError(f"no pose for robot {robot!r}: no token has a pose and the world gives none")

    def run(self, ctx: ActionContext) -> dict[str, Any]:
        params = self.params
        robot = params["robot"] if params["robot"] is not None else ctx.agent
        path = None
        for data in _tokens(ctx):
            path = _field(data, "path")
            if path is not None:
                break
        if path is None or len(path) == 0:
            raise PlanningError("no path: no input token has a path")
        position = self._position(ctx, robot)
        with ctx.stopwatch.measure("planning"):
            decision = check_track(path, position, step=params["step"], radius=params["radius"],
                                   reach=params["reach"])
        return {
            "robot": robot, "decision": decision.kind.value, "distance": round(decision.distance, 6),
            "point": None if decision.point is None else [round(v, 6) for v in decision.point],
            "index": decision.index, "nearest": decision.nearest, "position": [round(v, 6) for v in position],
            "path": [list(p) for p in path],
        }
