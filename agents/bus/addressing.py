"""Auto-addressing of a chain of modules (seed 002, §3).

Every module has a proximity sensor on its front face. A module whose front sensor
sees nothing is the head: it takes address 0 and tells the module behind it its
address; that module takes the next address and tells the one behind it, and so on
until the tail ("and so on until all the modules in the chain have auto-assigned an
address with respect to the activation of the proximity sensor").

Modelling choices:

* The notice goes to the module *behind* the sender, the one whose front face touches
  the sender's back face (the paper does not say how a module knows its neighbour on a
  shared bus; face contact, through the connector or the sensor, is the only way that
  does not need addresses). :func:`auto_address` routes it along ``behind``.
* A module whose front sensor is blocked waits for a notice; one that already has an
  address ignores further notices, so a ring (no free front) never starts and a loop in
  ``behind`` ends.
* Addresses are 0–253 (the paper: "self-addressing supports up to 254 device
  configurations"); a longer chain is an error, as are no head, several heads (two
  chains on one bus would both take address 0), and modules never reached.
* If the head leaves, the next module's front sensor frees, it runs the routine
  again and becomes address 0 ("inherit the leader function"): call
  :func:`auto_address` again with the new sensor readings.

Examples:
    >>> behind = {"m7": "m2", "m2": "m9", "m9": None}
    >>> auto_address(behind, front_free={"m7": True, "m2": False, "m9": False})
    {'m7': 0, 'm2': 1, 'm9': 2}
"""

from __future__ import annotations

from collections import deque
from collections.abc import Hashable, Mapping
from dataclasses import dataclass

from petriflow.agents.bus.errors import AddressingError

__all__ = ["MAX_MODULES", "AddressNotice", "AddressingError", "AddressingModule", "auto_address"]

#: Modules the addressing supports.
MAX_MODULES = 254


@dataclass(frozen=True)
class AddressNotice:
    """"My address is ``address``": sent by ``sender`` to the module behind it."""

    sender: Hashable
    address: int


class AddressingModule:
    """One module's addressing routine, as a state machine.

    Args:
        name: the module's identity (its serial number, say).
        front_free: the front proximity sensor sees nothing.

    Attributes:
        address: the address taken, or ``None`` while waiting.

    Examples:
        >>> head, tail = AddressingModule("a", front_free=True), AddressingModule("b", front_free=False)
        >>> notices = head.start(); tail.start()
        []
        >>> tail.receive(notices[0]), tail.address
        ([AddressNotice(sender='b', address=1)], 1)
    """

    def __init__(self, name: Hashable, front_free: bool) -> None:
        self.name = name
        self.front_free = front_free
        self.address: int | None = None

    def start(self) -> list[AddressNotice]:
        """Check the front sensor: the head takes address 0 and notifies the module behind."""
        if self.front_free and self.address is None:
            return self._take(0)
        return []

    def receive(self, notice: AddressNotice) -> list[AddressNotice]:
        """A notice from the module in front: take the next address, pass it on."""
        if self.address is not None or self.front_free:
            return []
        return self._take(notice.address + 1)

    def _take(self, address: int) -> list[AddressNotice]:
        if address >= MAX_MODULES:
            raise AddressingError(f"module {self.name!r}: address {address} is beyond the {MAX_MODULES} supported")
        self.address = address
        return [AddressNotice(self.name, address)]


def auto_address(behind: Mapping[Hashable, Hashable | None],
                 front_free: Mapping[Hashable, bool]) -> dict[Hashable, int]:
    """Run the addressing routine on a chain and return every module's address.

    Args:
        behind: for each module, the module whose front touches its back (``None`` at
            the tail).
        front_free: for each module, whether its front sensor is free.

    Raises:
        AddressingError: no head, several heads, a chain over 254 modules, or modules
            the notices never reached.

    Examples:
        >>> auto_address({"a": "b", "b": "a"}, {"a": False, "b": False})
        Traceback (most recent call last):
        ...
        petriflow.agents.bus.errors.AddressingError: no module has a free front sensor: nobody takes address 0
    """
    modules = {name: AddressingModule(name, front_free.get(name, False)) for name in behind}
    heads = [name for name, module in modules.items() if module.front_free]
    if not heads:
        raise AddressingError("no module has a free front sensor: nobody takes address 0")
    if len(heads) > 1:
        raise AddressingError(f"modules {sorted(map(repr, heads))} all have a free front sensor:"
                              " several would take address 0")
    notices: deque[AddressNotice] = deque()
    for module in modules.values():
        notices.extend(module.start())
    while notices:
        notice = notices.popleft()
        target = behind.get(notice.sender)
        if target is not None and target in modules:
            notices.extend(modules[target].receive(notice))
    missing = [name for name, module in modules.items() if module.address is None]
    if missing:
        raise AddressingError(f"modules {sorted(map(repr, missing))} were never reached by an address notice")
    return {name: module.address for name, module in modules.items() if module.address is not None}
