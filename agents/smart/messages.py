"""SMART command messages (seed 003, §2.3): action id, robot id, parameters, ``%``.

A command is a sequence of bytes: the action identifier (one byte), the robot's id
(one byte), then each parameter preceded by a comma; ``%`` ends the command, so a
stream of commands reads as ``cmd%cmd%...``. The paper's commands are seven bytes:
``[action][robot],[p1],[p2]%`` (bytes four and six are the parameters), e.g. "move
robot 3 to (X, Y)". Parameters are unsigned bytes, so positions travel in coarse cells
of ``resolution`` metres (:func:`to_cells`), 256 x 256 of them at most.

A parameter byte may itself equal ``,`` (44) or ``%`` (37); the decoder therefore
reads the frame by position (a comma every second byte) instead of splitting on
separators, and the encoder refuses nothing in 0..255.

Examples:
    >>> frame = encode(Command(ActionId.MOVE_TO, robot=3, params=(120, 44)))
    >>> frame
    b'\\x01\\x03,x,,%'
    >>> decode(frame + encode(Command(ActionId.STOP, robot=2)))
    [Command(action=<ActionId.MOVE_TO: 1>, robot=3, params=(120, 44)), Command(action=<ActionId.STOP: 2>, robot=2, params=())]
"""

from __future__ import annotations

import enum
from dataclasses import dataclass

from petriflow.errors import PetriflowError

__all__ = ["ActionId", "Command", "encode", "decode", "MessageError", "to_cells", "from_cells",
           "SEPARATOR", "END"]

SEPARATOR = ord(",")
END = ord("%")


class MessageError(PetriflowError):
    """A frame that is not a valid SMART command."""


class ActionId(enum.IntEnum):
    """Action identifiers of the commands the decision maker sends (one byte each)."""

    MOVE_TO = 1
    STOP = 2
    TURN = 3
    STAND_UP = 4
    HELP = 5
    HOLD = 6


@dataclass(frozen=True)
class Command:
    """One command for one robot."""

    action: ActionId
    robot: int
    params: tuple[int, ...] = ()


def encode(command: Command) -> bytes:
    """The command's bytes, ``%``-terminated.

    Raises:
        MessageError: an id or parameter outside 0..255.
    """
    values = [int(command.action), command.robot, *command.params]
    for value in values:
        if not 0 <= value <= 255:
            raise MessageError(f"{command}: {value} does not fit in one byte (0..255)")
    frame = bytearray([int(command.action), command.robot])
    for value in command.params:
        frame += bytes([SEPARATOR, value])
    frame.append(END)
    return bytes(frame)


def decode(stream: bytes) -> list[Command]:
    """Every command in ``stream`` (one or more ``%``-terminated frames).

    Raises:
        MessageError: naming the byte offset, for a truncated frame, a missing comma,
            or an unknown action id.
    """
    commands = []
    position = 0
    while position < len(stream):
        if len(stream) - position < 3:
            raise MessageError(f"truncated command at byte {position}")
        action_byte, robot = stream[position], stream[position + 1]
        try:
            action = ActionId(action_byte)
        except ValueError:
            raise MessageError(f"unknown action id {action_byte} at byte {position}") from None
        cursor = position + 2
        params = []
        while True:
            if cursor >= len(stream):
                raise MessageError(f"command at byte {position} has no '%' end")
            if stream[cursor] == END:
                break
            if stream[cursor] != SEPARATOR:
                raise MessageError(f"expected ',' or '%' at byte {cursor}")
            if cursor + 1 >= len(stream):
                raise MessageError(f"truncated command at byte {position}: parameter missing")
            params.append(stream[cursor + 1])
            cursor += 2
        commands.append(Command(action, robot, tuple(params)))
        position = cursor + 1
    return commands


def to_cells(x: float, y: float, resolution: float, origin: tuple[float, float] = (0.0, 0.0)) -> tuple[int, int]:
    """World metres to the byte-sized coarse cells a command carries.

    Raises:
        MessageError: the point is outside the 256 x 256 cells from ``origin``.

    Examples:
        >>> to_cells(1.0, 0.5, resolution=0.025)
        (40, 20)
    """
    cx, cy = round((x - origin[0]) / resolution), round((y - origin[1]) / resolution)
    if not (0 <= cx <= 255 and 0 <= cy <= 255):
        raise MessageError(f"point ({x}, {y}) is outside the 256 x 256 cells of {resolution} m")
    return cx, cy


def from_cells(cx: int, cy: int, resolution: float, origin: tuple[float, float] = (0.0, 0.0)) -> tuple[float, float]:
    """Coarse cells back to world metres (the cell's centre).

    Examples:
        >>> from_cells(40, 20, resolution=0.025)
        (1.0, 0.5)
    """
    return (origin[0] + cx * resolution, origin[1] + cy * resolution)
