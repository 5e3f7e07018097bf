"""The pieces of Graphviz's DOT language that petriflow's drawings are made of.

Both pictures of a net, drawn node by node (:mod:`petriflow.export`) and folded one box
per agent (:mod:`petriflow.fold`), write their DOT text with these: quoted ids that
stay distinct (:func:`quote`), HTML-like labels (:func:`html_text`), the tokens drawn
inside a place (:func:`tokens_text`), attribute lists (:func:`attributes`), and one look:
the font and the colours of agent clusters.

Examples:
    >>> tokens_text(7)
    '<FONT POINT-SIZE="10"><B>7</B></FONT>'
    >>> html_text("a < b\\nc"), attributes({"shape": "box", "label": quote("go")})
    ('a &lt; b<BR/>c', '[shape=box, label="go"]')
"""

from __future__ import annotations

import html
import re
from typing import Mapping

__all__ = ["CLUSTER_COLOURS", "FONT", "OUTCOME_COLOURS", "arc_look", "attributes", "html_text", "quote",
           "tokens_text"]

#: The font of every text in a drawing.
FONT = "Helvetica"
#: ``(fill, border)`` of each agent's cluster or box, in turn.
CLUSTER_COLOURS = (
    ("#eef5fc", "#6b9bc8"),
    ("#f1f8ec", "#7fae62"),
    ("#fdf3e7", "#d39a4f"),
    ("#f5effa", "#9c7dbf"),
    ("#eef8f7", "#5fa8a0"),
    ("#fbeff2", "#c77b90"),
)
#: Colour of the output arcs reserved for each routed action outcome (see :func:`arc_look`).
OUTCOME_COLOURS = {"failed": "#c0392b", "timeout": "#c77c02", "cancelled": "#7f7f7f"}
_TOKEN = "\u25cf"  # a black circle: one token

_CONTROL = re.compile(r"[\x00-\x08\x0b-\x1f\x7f]")
_BACKSLASHES_AT_RISK = re.compile(r'\\+(?=["\n]|\Z)')


def quote(text: str) -> str:
    """A DOT double-quoted string naming ``text``, distinct for distinct texts.

    Inside quotes Graphviz reads ``\\"`` as a quote, keeps ``\\\\`` as two
    backslashes and drops a backslash that ends a line. So quotes are escaped, and a
    run of backslashes just before a quote, a line break or the end (which Graphviz
    could misread) is doubled; every other text comes back exactly as it was.

    Examples:
        >>> print(quote('say "hi"'), quote("a:b/c d"))
        "say \\"hi\\"" "a:b/c d"
    """
    quoted = _BACKSLASHES_AT_RISK.sub(lambda run: run.group(0) * 2, text)
    return '"' + quoted.replace('"', '\\"') + '"'


def html_text(text: str) -> str:
    """``text`` as the content of a Graphviz HTML-like label (lines kept)."""
    text = text.replace("\r\n", "\n").replace("\r", "\n").replace("\t", " ")
    text = _CONTROL.sub("\ufffd", text)
    return "<BR/>".join(html.escape(line, quote=True) for line in text.split("\n"))


def attributes(attrs: Mapping[str, str]) -> str:
    """A DOT attribute list: ``[key=value, ...]`` (values already quoted where needed)."""
    return "[" + ", ".join(f"{key}={value}" for key, value in attrs.items()) + "]"


def tokens_text(count: int) -> str:
    """Tokens drawn inside a place: dots for 1 to 4, the number from 5 on."""
    if count == 0:
        return " "
    if count <= 4:
        rows = {1: [1], 2: [2], 3: [2, 1], 4: [2, 2]}[count]
        dots = "<BR/>".join(" ".join([_TOKEN] * n) for n in rows)
        return f'<FONT POINT-SIZE="{12 if count == 1 else 8}">{dots}</FONT>'
    digits = len(str(count))
    size = {1: 10, 2: 10, 3: 9, 4: 8}.get(digits, 7)  # from 6 digits on it spills over the rim
    return f'<FONT POINT-SIZE="{size}"><B>{count}</B></FONT>'


def arc_look(outcome: str | None, weight: int = 1) -> dict[str, str]:
    """How an arc is drawn: an output arc reserved for an action outcome (``failed``,
    ``timeout``, ``cancelled``) is dashed in the outcome's colour (:data:`OUTCOME_COLOURS`)
    and named by it, so a failure route never looks like one more branch of an AND-split;
    a weight above 1 is written beside the arc. Texts are ``xlabel``: Graphviz places them
    beside the arc after the layout, not on top of it.

    Examples:
        >>> arc_look(None), arc_look(None, 2)
        ({}, {'xlabel': '"2"'})
        >>> arc_look("failed")["style"], arc_look("failed", 3)["xlabel"]
        ('dashed', '"failed ×3"')
    """
    attrs: dict[str, str] = {}
    text = "" if weight <= 1 else str(weight)
    if outcome is not None and outcome != "ok":
        colour = OUTCOME_COLOURS.get(outcome, "#7f7f7f")
        text = outcome if weight <= 1 else f"{outcome} \u00d7{weight}"
        attrs.update({"style": "dashed", "color": f'"{colour}"', "fontcolor": f'"{colour}"'})
    if text:
        attrs["xlabel"] = quote(text)
    return attrs
