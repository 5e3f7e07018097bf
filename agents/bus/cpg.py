"""The central pattern generator of the EMERGE chain: one phase oscillator per module.

Seed 002's equations (1) and (2) drive module ``i``'s motor with

* ``θi = xi + ri·cos(φi)`` (offset ``x``, amplitude ``r``, phase ``φ``), and
* ``φi' = wi + Σj wij·sin(φj − φi − φij)`` over the chain neighbours ``j`` of ``i``,

with ``wi = 0.5`` and ``wij = 0.8`` (algorithms 1 and 2 set them so).

**Sign convention.** The paper prints the coupling as ``sin(φi − φj + θij)``. With that
sign the pull is repulsive: for two oscillators the difference ``ψ = φi − φj`` obeys
``ψ' = 2·w·sin(ψ + θij)``, whose fixed point ``ψ = −θij`` is unstable, so the chain would
settle half a turn away from the intended lag. We use the usual form
``sin(φj − φi − φij)`` (Kuramoto; Ijspeert's CPGs), for which ``φj − φi = φij`` is
stable. The desired lags make a travelling wave from the head (address 0) backwards:
each module trails the one in front of it by ``lag`` (``φ(i+1) = φi − lag``), i.e.
``φij = (i − j)·lag``. The paper gives no lag; the default is ``2π / 3``.

**Units.** ``w`` and the coupling are in rad/s as printed (no 2π factor): a period of
4π ≈ 12.6 s.

**Information.** Module ``i`` does not see its neighbours' phases: it uses the phase in
the last message it read from each (:meth:`CpgChain.hear`), held constant until the
next one; a neighbour it never heard from does not couple. This is the paper's
reception routine, which stores the received φ, x and r and calls ``Update`` (the
pseudo-code assigns them to the module's own ``φi``, ``xi``, ``ri``; equation (2) needs
them as the neighbour's ``φj``, which is how we use them). With ``extrapolate=True`` a
module instead advances a stored phase by ``w`` times its age (dead reckoning), which
hides most of the effect of lost messages. Stale phases are what make loss degrade
locking: a module chasing an old phase settles ahead of it by
``asin(w / wij)`` and stalls until fresh news comes.

**Integration.** Classic fourth-order Runge–Kutta with a fixed step ``dt`` (known
phases are constant within a step).

Examples:
    >>> chain = CpgChain(3, phases=[0.0, 2.0, 4.0])
    >>> chain.listen_continuously = True              # perfect communication
    >>> chain.advance(40.0)
    >>> phase_error(chain.phases, chain.parameters.lag) < 1e-6
    True
    >>> round(motor_angle(0.1, 0.5, 0.0), 2)
    0.6
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

__all__ = ["CpgChain", "CpgParameters", "motor_angle", "phase_error", "wrap"]


@dataclass(frozen=True)
class CpgParameters:
    """The oscillators' constants (the same in every module).

    Attributes:
        frequency: the intrinsic rate ``wi`` (rad/s).
        coupling: the neighbour weight ``wij`` (rad/s).
        lag: the phase by which each module trails the one in front (rad).
        offset: ``xi`` (rad).
        amplitude: ``ri`` (rad).
        dt: integration step (s); 20 ms, the modules' control step.
        extrapolate: advance stored neighbour phases by ``frequency × age``.
    """

    frequency: float = 0.5
    coupling: float = 0.8
    lag: float = 2.0 * math.pi / 3.0
    offset: float = 0.0
    amplitude: float = 0.5
    dt: float = 0.02
    extrapolate: bool = False


def wrap(angle: float | np.ndarray) -> float | np.ndarray:
    """An angle brought into [−π, π).

    Examples:
        >>> round(wrap(3 * math.pi), 6), round(wrap(-0.5), 6)
        (-3.141593, -0.5)
    """
    return (angle + math.pi) % (2.0 * math.pi) - math.pi


def motor_angle(offset: float, amplitude: float, phase: float) -> float:
    """Equation (1): ``θ = x + r·cos(φ)``."""
    return offset + amplitude * math.cos(phase)


def phase_error(phases: Sequence[float] | np.ndarray, lag: float) -> float:
    """Mean phase-locking error of a chain: the mean over neighbouring pairs of
    ``|wrap(φi − φ(i+1) − lag)|`` in radians (0 when every module trails the one in
    front by exactly ``lag``; about π/2 for unrelated phases).

    Examples:
        >>> phase_error([1.0, 0.5, 0.0], 0.5)
        0.0
        >>> round(phase_error([0.0, 0.0], 0.5), 3)
        0.5
    """
    values = np.asarray(phases, dtype=float)
    if values.size < 2:
        return 0.0
    return float(np.mean(np.abs(wrap(values[:-1] - values[1:] - lag))))


class CpgChain:
    """The oscillators of a chain of ``n`` modules, each knowing only what it heard.

    Args:
        n: modules (addresses 0 … n − 1, address 0 at the head).
        parameters: the shared constants.
        phases: initial phases (default zeros).

    Attributes:
        phases: current phases ``φ`` (numpy array).
        time: simulated time of the phases.
        listen_continuously: every module knows its neighbours' current phases (no bus);
            the reference for locking without loss.
    """

    def __init__(self, n: int, parameters: CpgParameters | None = None,
                 phases: Sequence[float] | None = None) -> None:
        self.parameters = parameters or CpgParameters()
        self.n = n
        self.phases = np.zeros(n) if phases is None else np.array(phases, dtype=float)
        if self.phases.shape != (n,):
            raise ValueError(f"{n} modules need {n} phases, got {self.phases.shape}")
        self.time = 0.0
        self.listen_continuously = False
        # Each module's two couplings, towards the module in front (j = i − 1, desired
        # φj − φi = +lag) and behind (j = i + 1, −lag): columns 0 and 1 of these arrays.
        self._exists = np.ones((n, 2), dtype=bool)
        self._exists[0, 0] = self._exists[n - 1, 1] = False
        self._bias = np.array([self.parameters.lag, -self.parameters.lag])
        self._heard = np.zeros((n, 2))
        self._heard_at = np.full((n, 2), np.nan)

    @staticmethod
    def _side(module: int, neighbour: int) -> int | None:
        """Column of ``neighbour`` in ``module``'s coupling arrays (None: not a neighbour)."""
        return {-1: 0, 1: 1}.get(neighbour - module)

    def hear(self, module: int, neighbour: int, phase: float) -> None:
        """``module`` read a message carrying ``neighbour``'s phase (ignored unless they
        are neighbours)."""
        side = self._side(module, neighbour)
        if side is not None and 0 <= neighbour < self.n:
            self._heard[module, side] = phase
            self._heard_at[module, side] = self.time

    def knows(self, module: int, neighbour: int) -> bool:
        """Whether ``module`` has heard from ``neighbour``."""
        side = self._side(module, neighbour)
        return side is not None and not math.isnan(self._heard_at[module, side])

    def angles(self) -> np.ndarray:
        """Equation (1) for every module: the motor angles ``θ``."""
        p = self.parameters
        return p.offset + p.amplitude * np.cos(self.phases)

    def _rate(self, phases: np.ndarray, targets: np.ndarray, mask: np.ndarray) -> np.ndarray:
        p = self.parameters
        pull = np.sin(targets - phases[:, None] - self._bias)
        return p.frequency + p.coupling * (pull * mask).sum(axis=1)

    @staticmethod
    def _neighbours_of(phases: np.ndarray) -> np.ndarray:
        """Each module's front and back neighbours' current phases (0 where none)."""
        around = np.zeros((phases.size, 2))
        around[1:, 0] = phases[:-1]
        around[:-1, 1] = phases[1:]
        return around

    def step(self, dt: float | None = None) -> None:
        """One Runge–Kutta step of ``dt`` (default the parameters' step)."""
        h = self.parameters.dt if dt is None else dt
        continuous = self.listen_continuously
        if continuous:
            mask = self._exists
            targets = self._heard  # unused
        else:
            mask = self._exists & ~np.isnan(self._heard_at)
            targets = self._heard
            if self.parameters.extrapolate:
                targets = targets + self.parameters.frequency * np.nan_to_num(self.time - self._heard_at)
        drift = self.parameters.frequency if self.parameters.extrapolate and not continuous else 0.0

        def rate(phases: np.ndarray, tau: float) -> np.ndarray:
            if continuous:  # everyone sees everyone's current phase: neighbours move within the step
                return self._rate(phases, self._neighbours_of(phases), mask)
            return self._rate(phases, targets + drift * tau, mask)

        phi = self.phases
        k1 = rate(phi, 0.0)
        k2 = rate(phi + 0.5 * h * k1, 0.5 * h)
        k3 = rate(phi + 0.5 * h * k2, 0.5 * h)
        k4 = rate(phi + h * k3, h)
        self.phases = phi + h / 6.0 * (k1 + 2.0 * k2 + 2.0 * k3 + k4)
        self.time += h

    def advance(self, duration: float) -> None:
        """Integrate for ``duration`` seconds in fixed steps (a last shorter step lands
        exactly on the end)."""
        end = self.time + duration
        dt = self.parameters.dt
        while self.time + dt <= end + 1e-12:
            self.step(dt)
        if end - self.time > 1e-12:
            self.step(end - self.time)
