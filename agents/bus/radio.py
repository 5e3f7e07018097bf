"""The radio link of the ZigBee bus: received power and the chance a frame survives.

A frame between two XBee radios is lost when its bits do not survive the channel. We
compute that from the received signal strength:

* **RSSI** (:meth:`RadioLink.rssi`): petriflow's one log-distance path loss
  (:class:`petriflow.runtime.radio.LogDistance`, the formula every radio channel
  shares), ``RSSI = tx_power − L(1 m) − 10·n·log10(d / 1 m) − walls`` plus, per frame,
  a zero-mean Gaussian *shadowing* term of ``shadowing_db`` standard deviation (the
  body of the module in between, the robot moving). Distances below ``min_distance``
  count as ``min_distance``: the log law means nothing in the antennas' near field.
* **Bit errors** (:func:`oqpsk_bit_error_rate`): 802.15.4's 2.4 GHz O-QPSK with
  16-ary quasi-orthogonal spreading, the standard's approximation
  ``BER = 8/15 · 1/16 · Σ_{k=2..16} (−1)^k C(16, k) exp(20·SINR·(1/k − 1))``
  (SINR linear). Interference adds to the noise floor in milliwatts.
* **Frame errors** (:func:`packet_error_rate`): bit errors are independent, so a
  frame of ``b`` bits survives with probability ``(1 − BER)^b``; no capture, no
  partial frames.

Defaults: 0 dBm transmit power (an XBee Series 1/2 without the PRO amplifier), 40 dB
at 1 m (free space at 2.4 GHz), exponent 2, a noise floor of −93 dBm (which puts the
1 % frame-error point of a short frame near −92 dBm, the XBee's rated sensitivity),
no shadowing and no interference. With modules a few centimetres apart this link
loses essentially nothing; losses appear only when you add shadowing, walls,
distance or interference.

Examples:
    >>> link = RadioLink()
    >>> round(link.rssi(1.0), 1), round(link.rssi(10.0), 1)
    (-40.0, -60.0)
    >>> round(packet_error_rate(0.0, 208), 3)      # SINR 0 dB: 3 % of 26-byte frames lost
    0.033
    >>> packet_error_rate(10.0, 208) < 1e-12
    True
"""

from __future__ import annotations

import math
import random
from dataclasses import dataclass, field

from petriflow.runtime.radio import LogDistance

__all__ = ["RadioLink", "oqpsk_bit_error_rate", "packet_error_rate"]

_TERMS = [(k, (-1) ** k * math.comb(16, k)) for k in range(2, 17)]


def oqpsk_bit_error_rate(sinr_db: float) -> float:
    """Bit error rate of 802.15.4's 2.4 GHz O-QPSK at ``sinr_db``.

    Examples:
        >>> oqpsk_bit_error_rate(-3.0) > oqpsk_bit_error_rate(0.0) > oqpsk_bit_error_rate(3.0)
        True
    """
    if sinr_db < -20.0:
        return 0.5
    sinr = 10.0 ** (sinr_db / 10.0)
    total = sum(sign * math.exp(20.0 * sinr * (1.0 / k - 1.0)) for k, sign in _TERMS)
    return min(0.5, max(0.0, 8.0 / 15.0 / 16.0 * total))


def packet_error_rate(sinr_db: float, bits: int) -> float:
    """Probability that a frame of ``bits`` bits has at least one bit error."""
    return 1.0 - (1.0 - oqpsk_bit_error_rate(sinr_db)) ** bits


@dataclass(frozen=True)
class RadioLink:
    """Path loss and noise of the radios of one ZigBee bus (all links share them).

    Attributes:
        tx_power_dbm: transmit power.
        reference_loss_db: path loss at 1 m.
        exponent: path-loss exponent.
        noise_floor_dbm: receiver noise in the 2 MHz channel.
        interference_dbm: other 2.4 GHz traffic (Wi-Fi...) at the receiver, or ``-inf``.
        shadowing_db: standard deviation of the per-frame Gaussian shadowing.
        min_distance: distances below this count as this (metres).
        path: the path loss (:class:`~petriflow.runtime.radio.LogDistance`) of these
            parameters.
    """

    tx_power_dbm: float = 0.0
    reference_loss_db: float = 40.0
    exponent: float = 2.0
    noise_floor_dbm: float = -93.0
    interference_dbm: float = -math.inf
    shadowing_db: float = 0.0
    min_distance: float = 0.05
    path: LogDistance = field(init=False, repr=False, compare=False)

    def __post_init__(self) -> None:
        object.__setattr__(self, "path", LogDistance(self.tx_power_dbm, self.reference_loss_db, self.exponent,
                                                     self.min_distance))

    def rssi(self, distance: float, walls_db: float = 0.0) -> float:
        """Mean received power in dBm at ``distance`` metres through ``walls_db`` of walls."""
        return self.path.rssi(distance, walls_db)

    def noise_dbm(self) -> float:
        """Noise plus interference in dBm."""
        if self.interference_dbm == -math.inf:
            return self.noise_floor_dbm
        return 10.0 * math.log10(10.0 ** (self.noise_floor_dbm / 10.0) + 10.0 ** (self.interference_dbm / 10.0))

    def delivery_probability(self, distance: float, bits: int) -> float:
        """Chance a frame of ``bits`` bits arrives intact at the mean RSSI (no shadowing)."""
        return 1.0 - packet_error_rate(self.rssi(distance) - self.noise_dbm(), bits)

    def survives(self, distance: float, bits: int, rng: random.Random) -> bool:
        """Draw whether one frame arrives intact (shadowing drawn for this frame).

        Examples:
            >>> RadioLink().survives(0.1, 208, random.Random(1))
            True
            >>> RadioLink(tx_power_dbm=-60.0).survives(10.0, 208, random.Random(1))
            False
        """
        rssi = self.rssi(distance)
        if self.shadowing_db > 0.0:
            rssi += rng.gauss(0.0, self.shadowing_db)
        error = packet_error_rate(rssi - self.noise_dbm(), bits)
        if error <= 0.0:
            return True
        return rng.random() >= error
