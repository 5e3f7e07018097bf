"""Reading and writing nets: petriflow YAML and standard PNML.

:func:`load_net` picks the reader from the file's ending (``.yaml``/``.yml`` or
``.pnml``/``.xml``), falling back to the first non-blank character (``<`` means XML).
"""

from __future__ import annotations

from pathlib import Path

from petriflow.errors import NetFormatError
from petriflow.net import Net

__all__ = ["load_net", "save_net"]

_YAML = {".yaml", ".yml"}
_PNML = {".pnml", ".xml"}


def _format_of(path: Path) -> str:
    suffix = path.suffix.lower()
    if suffix in _YAML:
        return "yaml"
    if suffix in _PNML:
        return "pnml"
    from petriflow.io.files import read_text_file

    return "pnml" if read_text_file(path).lstrip().startswith("<") else "yaml"


def load_net(path: str | Path) -> Net:
    """Read a net from a YAML or PNML file.

    Raises:
        NetFormatError: the file is missing, unreadable or not a valid net; the message
            names the file and, where known, the line and element.
    """
    path = Path(path)
    if not path.is_file():
        raise NetFormatError("no such file", path=str(path))
    if _format_of(path) == "pnml":
        from petriflow.io.pnml import load_pnml

        return load_pnml(path)
    from petriflow.io.yaml import load_yaml

    return load_yaml(path)


def save_net(net: Net, path: str | Path, format: str | None = None) -> None:
    """Write ``net`` as YAML or PNML (by ``format`` or by the file's ending)."""
    path = Path(path)
    format = format or ("pnml" if path.suffix.lower() in _PNML else "yaml")
    if format == "pnml":
        from petriflow.io.pnml import save_pnml

        save_pnml(net, path)
    else:
        from petriflow.io.yaml import save_yaml

        save_yaml(net, path)
