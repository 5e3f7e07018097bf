"""What the PNML tests share: reading inline documents, with or without warnings."""

from __future__ import annotations

import textwrap
import warnings
from pathlib import Path

import pytest

from petriflow.errors import NetFormatError
from petriflow.io.pnml import (
    PNML_NAMESPACE,
    PTNET_TYPE,
    PnmlWarning,
    load_pnml,
    loads_pnml,
)
from petriflow.net import Net

REPO = Path(__file__).resolve().parents[2]
DATA = Path(__file__).resolve().parent / "data"
ISO = PNML_NAMESPACE


def tidy(text: str) -> str:
    """Inline test documents lose their indentation; written documents stay byte-exact."""
    return text if text.startswith("<") else textwrap.dedent(text).strip()


def read(text: str, path: str = "net.pnml") -> Net:
    """Read PNML text, failing the test on any warning."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", PnmlWarning)
        return loads_pnml(tidy(text), path=path)


def read_warned(text: str, path: str = "net.pnml") -> tuple[Net, list[str]]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        net = loads_pnml(tidy(text), path=path)
    return net, [str(w.message) for w in caught if issubclass(w.category, PnmlWarning)]


def load_warned(path: Path) -> tuple[Net, list[str]]:
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        net = load_pnml(path)
    return net, [str(w.message) for w in caught if issubclass(w.category, PnmlWarning)]


def error_of(text: str) -> NetFormatError:
    with pytest.raises(NetFormatError) as info:
        loads_pnml(tidy(text), path="bad.pnml")
    return info.value


def iso(body: str, net_type: str = PTNET_TYPE) -> str:
    """An ISO document holding one net with one page around ``body``."""
    return (f'<pnml xmlns="{ISO}"><net id="n" type="{net_type}"><page id="pg">'
            f'{textwrap.dedent(body)}</page></net></pnml>')


def arcs_of(net: Net) -> set[tuple[str, str, int]]:
    return {(a.source, a.target, a.weight) for a in net.arcs}
