"""Standard PNML, read and written: lossless where the file is valid, loud where not.

The reader (:mod:`petriflow.io.pnml_read`) takes ISO/IEC 15909-2 P/T nets and the
dialects other tools write (PM4Py/ProM, WoPeD, JARP, PIPE, SNAKES: the table of
:mod:`petriflow.io.pnml_dialects`). It parses with defusedxml
(:mod:`petriflow.io.safe_xml`) and refuses DTDs and entities, raises :class:`~petriflow.errors.NetFormatError`
with the line for anything malformed or not a P/T net, and emits one
:class:`PnmlWarning` per kind of content a petriflow net cannot hold.

The writer (:mod:`petriflow.io.pnml_write`) writes ISO PNML that PM4Py, ProM and other
tools open, and keeps petriflow's own data (actions, parameters, guards, subnets,
operators...) in ``<toolspecific tool="petriflow">`` so that reading it back gives the
same net.

Examples:
    >>> from petriflow.net import Net
    >>> net = Net("relay", label="Hand-over")
    >>> _ = net.add_subnet("arm", agent="robot_1")
    >>> _ = net.add_place("i", tokens=1)
    >>> _ = net.add_place("o")
    >>> _ = net.add_transition("grab", action="arm.grab", params={"force": 2.5}, subnet="arm")
    >>> _ = net.add_arc("i", "grab"); _ = net.add_arc("grab", "o", weight=2)
    >>> net.set_final_marking({"o": 2})
    >>> text = dumps_pnml(net)
    >>> '<inscription>' in text and '<finalmarkings>' in text
    True
    >>> back = loads_pnml(text)
    >>> back, back.transition("grab").params, back.final_marking
    (<Net 'relay': 2 places, 1 transitions, 2 arcs>, {'force': 2.5}, Marking({'o': 2}))
    >>> back.structure() == net.structure()
    True
"""

from __future__ import annotations

from petriflow.io.pnml_dialects import (
    PETRIFLOW_TOOL,
    PETRIFLOW_TOOL_VERSION,
    PNML_NAMESPACE,
    PT_NET_TYPES,
    PTNET_TYPE,
    WOPED_OPERATOR_TYPES,
)
from petriflow.io.pnml_read import PnmlWarning, load_pnml, loads_pnml
from petriflow.io.pnml_write import dumps_pnml, save_pnml

__all__ = [
    "load_pnml",
    "loads_pnml",
    "dumps_pnml",
    "save_pnml",
    "PnmlWarning",
    "PNML_NAMESPACE",
    "PTNET_TYPE",
    "PT_NET_TYPES",
    "WOPED_OPERATOR_TYPES",
    "PETRIFLOW_TOOL",
    "PETRIFLOW_TOOL_VERSION",
]
