"""A robot's bid for a zone: the cost of eq. 6 of seed 004, for every robot and zone at once.

The paper (§2.1, eq. 6) prices zone ``z_j`` for robot ``r_i`` as::

    Cost_ij = α (Σ_{k<j} A_ik P_ij + P_ij)  +  β log(LW)^(Σ_{k<j} A_ik) Σ_{k<j} A_ik  +  γ (1 − E_i)

with ``n_i = Σ_{k<j} A_ik`` the zones already allocated to the robot (those offered
before ``z_j``), ``P_ij`` the travel time from the robot's current position ``c_i`` to
the zone's position ``g_j`` (Euclidean distance over the robot's speed), ``L × W`` the
workspace's area and ``E_i`` the accuracy of the robot's range sensor (1 = exact).
Read term by term, exactly as printed:

* travel: ``(n_i + 1) · P_ij``: the sum over ``k`` multiplies ``P_ij`` (not ``P_ik``),
  so the robot's travel time to this zone counts once more for every zone it already
  holds;
* load: ``log(LW) ** n_i · n_i``: the logarithm of the area raised to the number of
  zones held, times that number; 0 for a robot with nothing yet. It grows
  exponentially, so it spreads zones over the team;
* sensor: ``1 − E_i``.

Nothing is normalised: ``P`` is in seconds, the other two terms are pure numbers, and
``α + β + γ = 1`` (:class:`Weights`). The paper does not give the logarithm's base; the
natural logarithm is the default (``log_base``). Table 1: ``α = β = γ = 1/3``,
``E_i = 1``; §4.1: ``L × W = 32 × 22 m²``.

Examples:
    Robot 0 holds one zone already, robot 1 none; both 5 m (5 s at 1 m/s) from the
    zone they are not standing on:

    >>> costs = cost_matrix([(0, 0), (3, 4)], [(3, 4), (0, 0)], allocated=[1, 0], speed=1.0)
    >>> costs.round(3).tolist()
    [[5.519, 2.186], [0.0, 1.667]]
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from petriflow.agents.bidding.errors import BiddingError

__all__ = [
    "AREA_M2",
    "SPEED_M_S",
    "Weights",
    "travel_times",
    "load_term",
    "bid_costs",
    "cost_matrix",
]

#: The workspace's area L × W of §4.1 (32 m × 22 m).
AREA_M2 = 32.0 * 22.0
#: The robots' speed turning distance into the travel time ``P_ij`` (m/s), and their
#: cruise speed. The paper gives none; 0.4 m/s is the speed at which Stage 3.2 (the
#: paper's simulator) drives a position model to a goal pose (``max_speed_x`` of its
#: position controller, ``libstage/model_position.cc``; it turns at up to 1 rad/s).
SPEED_M_S = 0.4


@dataclass(frozen=True)
class Weights:
    """The constant weights of eq. 6: α (travel), β (load), γ (sensor); they sum to 1.

    Examples:
        >>> Weights()
        Weights(alpha=0.333..., beta=0.333..., gamma=0.333...)
        >>> Weights(0.5, 0.5, 0.5)
        Traceback (most recent call last):
        ...
        petriflow.agents.bidding.errors.BiddingError: eq. 6 weights must be >= 0 and sum to 1, got 0.5 + 0.5 + 0.5
    """

    alpha: float = 1.0 / 3.0
    beta: float = 1.0 / 3.0
    gamma: float = 1.0 / 3.0

    def __post_init__(self) -> None:
        values = (self.alpha, self.beta, self.gamma)
        if not all(math.isfinite(v) and v >= 0 for v in values) or abs(sum(values) - 1.0) > 1e-9:
            raise BiddingError(f"eq. 6 weights must be >= 0 and sum to 1, got {' + '.join(f'{v:g}' for v in values)}")


def _points(points: Any, what: str) -> np.ndarray:
    array = np.asarray(points, dtype=float)
    if array.ndim == 1 and array.size == 0:
        array = array.reshape(0, 2)
    if array.ndim != 2 or array.shape[1] < 2:
        raise BiddingError(f"{what} are (x, y) pairs, got an array of shape {array.shape}")
    return array[:, :2]


def travel_times(positions: Any, zones: Any, speed: float = SPEED_M_S) -> np.ndarray:
    """``P_ij``: seconds from each robot's position to each zone's position, straight line.

    Args:
        positions: ``(m, 2)`` robot positions ``c_i`` (extra columns, e.g. a heading,
            are ignored).
        zones: ``(z, 2)`` zone positions ``g_j``.
        speed: the robots' speed (m/s).

    Returns:
        A float array of shape ``(m, z)``.

    Examples:
        >>> travel_times([(0, 0, 1.57), (1, 0, 0.0)], [(3, 4)], speed=0.5).tolist()
        [[10.0], [8.94427190999916]]
    """
    if not (math.isfinite(speed) and speed > 0):
        raise BiddingError(f"speed must be > 0 m/s, got {speed!r}")
    robots, goals = _points(positions, "robot positions"), _points(zones, "zone positions")
    delta = robots[:, None, :] - goals[None, :, :]
    return np.hypot(delta[..., 0], delta[..., 1]) / speed


def load_term(allocated: Any, area: float = AREA_M2, log_base: float = math.e) -> np.ndarray:
    """The unweighted load term of eq. 6, ``log(LW) ** n · n``, for each count ``n``.

    Past ``float64``'s range (``n`` above about 370 for the natural logarithm of the
    paper's area) the term is ``inf``.

    Examples:
        >>> load_term([0, 1, 2]).round(3).tolist()
        [0.0, 6.557, 85.983]
        >>> load_term([1], log_base=10).round(3).tolist()
        [2.848]
    """
    if not (math.isfinite(area) and area > 1.0):
        raise BiddingError(f"the workspace's area must be > 1 m², got {area!r}")
    if not (math.isfinite(log_base) and log_base > 1.0):
        raise BiddingError(f"the logarithm's base must be > 1, got {log_base!r}")
    counts = np.asarray(allocated, dtype=float)
    if np.any(counts < 0):
        raise BiddingError("allocated zone counts must be >= 0")
    base = math.log(area) / math.log(log_base)
    with np.errstate(over="ignore"):
        return np.power(base, counts) * counts


def bid_costs(travel: Any, allocated: Any = 0, accuracy: Any = 1.0, *, area: float = AREA_M2,
              weights: Weights = Weights(), log_base: float = math.e) -> np.ndarray:
    """Eq. 6 from travel times already computed.

    Args:
        travel: ``P``, shape ``(m, z)`` (or ``(m,)`` for one zone).
        allocated: ``n_i``, zones each robot already holds, shape ``(m,)`` or a scalar.
        accuracy: ``E_i`` from 0 to 1, shape ``(m,)`` or a scalar.
        area: ``L × W`` in m².
        weights: α, β, γ.
        log_base: the base of the logarithm of the load term.

    Returns:
        Costs, the shape of ``travel``.

    Examples:
        >>> bid_costs([[6.0], [3.0]], allocated=[0, 1], accuracy=[1.0, 0.7]).round(3).tolist()
        [[2.0], [4.286]]
    """
    travel = np.asarray(travel, dtype=float)
    robots = travel.shape[0] if travel.ndim else 1
    counts = np.broadcast_to(np.asarray(allocated, dtype=float), (robots,))
    sensor = np.broadcast_to(np.asarray(accuracy, dtype=float), (robots,))
    if np.any((sensor < 0) | (sensor > 1)):
        raise BiddingError("sensor accuracy E_i must be from 0 to 1")
    shape = (robots,) + (1,) * (travel.ndim - 1)
    fixed = weights.beta * load_term(counts, area, log_base) + weights.gamma * (1.0 - sensor)
    return weights.alpha * (counts + 1.0).reshape(shape) * travel + fixed.reshape(shape)


def cost_matrix(positions: Any, zones: Any, allocated: Any = 0, accuracy: Any = 1.0, *,
                speed: float = SPEED_M_S, area: float = AREA_M2, weights: Weights = Weights(),
                log_base: float = math.e) -> np.ndarray:
    """Eq. 6 for every robot (rows) and zone (columns), the robots holding ``allocated`` zones.

    Examples:
        >>> cost_matrix([(0, 0)], [(1, 0), (2, 0)], speed=1.0).round(3).tolist()
        [[0.333, 0.667]]
        >>> cost_matrix([(0, 0)], [(1, 0)], allocated=1, speed=1.0).round(3).tolist()
        [[2.852]]
    """
    return bid_costs(travel_times(positions, zones, speed), allocated, accuracy, area=area, weights=weights,
                     log_base=log_base)
